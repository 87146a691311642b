// Planar pose integration of a differential-drive base (REP-103: x forward, y left, theta CCW).
#pragma once

#include <cmath>
#include <cstdint>

#include "odo/hal/angle.hpp"
#include "odo/odometry/error_model.hpp"
#include "odo/odometry/kinematics.hpp"

namespace odo {

// Pose in the odometry frame. theta is cumulative (not wrapped) [rad].
struct Pose2 {
  double x = 0.0;      // [m]
  double y = 0.0;      // [m]
  double theta = 0.0;  // [rad], cumulative: two full CCW turns give 4*pi
};

// SetPose: a request to replace the pose estimate, the one set-pose type of every room (the
// loop's command, the CAN SetPose frame's content, the ROS 2 set_pose topic's pose). Here, the
// lowest room that the loop, protocol/ and ros2/ all see. Taken as exact: the loop zeroes the
// pose covariance.
struct SetPose {
  Pose2 pose;
};

// Below this half-angle [rad] half_angle() uses Taylor series, exact to double precision: the
// first dropped terms are h^9/9! < 6e-18 (sin) and h^10/10! < 3e-20 (cos) for |h| <= 0.05.
inline constexpr double kHalfAngleSeriesLimit = 0.05;
// Below this half-angle (a turn of 4 rad/s at 1 kHz, 0.4 rad/s at 100 Hz) the series stop at h^4:
// the first dropped terms are h^6/7! < 1.3e-20 (sinc) and h^6/6! < 8.9e-20 (cos) of the leading 1
// (under 2^-63), so the short and the long series agree to the last bit or one ulp.
inline constexpr double kHalfAngleShortSeriesLimit = 0.002;

// Sine, cosine and sinc of the half-angle h of one step's turn.
struct HalfAngle {
  double s;     // sin(h)
  double c;     // cos(h)
  double sinc;  // sin(h)/h, 1 at h = 0
};

// half_angle: sin, cos and sinc of h [rad]; series (no library call) below
// kHalfAngleSeriesLimit, where the ticks of a loop almost always are.
inline HalfAngle half_angle(double h) noexcept {
  const double abs_h = std::fabs(h);
  if (abs_h < kHalfAngleShortSeriesLimit) {
    const double h2 = h * h;
    const double sinc = 1.0 - h2 / 6.0 * (1.0 - h2 / 20.0);
    const double c = 1.0 - h2 / 2.0 * (1.0 - h2 / 12.0);
    return {h * sinc, c, sinc};
  }
  if (abs_h < kHalfAngleSeriesLimit) {
    const double h2 = h * h;
    const double sinc = 1.0 - h2 / 6.0 * (1.0 - h2 / 20.0 * (1.0 - h2 / 42.0 * (1.0 - h2 / 72.0)));
    const double c = 1.0 - h2 / 2.0 * (1.0 - h2 / 12.0 * (1.0 - h2 / 30.0 * (1.0 - h2 / 56.0)));
    return {h * sinc, c, sinc};
  }
  const double s = std::sin(h);
  return {s, std::cos(h), s / h};
}

// arc_step: exact pose change for wheel travels d_left, d_right [m] on a constant-curvature arc
// of a base with wheelbase b [m]; stable for any turn, including none and on-the-spot.
Pose2 arc_step(const Pose2& p, double d_left, double d_right, double b) noexcept;

// arc_step_icr: arc_step for a skid-steer base whose instantaneous centre of rotation lies x_icr
// [m] ahead of the centre point (Mandow et al. 2007): the centre also slides sideways by
// -x_icr * dtheta over the arc. arc_step when x_icr is 0.
Pose2 arc_step_icr(const Pose2& p, double d_left, double d_right, double b, double x_icr) noexcept;

// report_step: UMBmark report Eq. 2.3-2.6 (heading updated first, then a straight chord along
// the new heading); kept for comparison with the exact arc.
Pose2 report_step(const Pose2& p, double d_left, double d_right, double b) noexcept;

// HeadingRotor: sin and cos of a heading carried from step to step by the angle-sum identities
// (no trigonometric call per step), re-derived from the heading itself every `resync_steps`
// steps so that the rotated pair never drifts. Used by the loop's PoseIntegrator and by the
// simulated robot's ground truth.
class HeadingRotor {
 public:
  explicit HeadingRotor(std::uint32_t resync_steps) : resync_steps_(resync_steps) {}
  // reset: sin and cos of theta [rad], exactly.
  void reset(double theta) noexcept {
    s_ = std::sin(theta);
    c_ = std::cos(theta);
    steps_ = 0;
  }
  double sin() const noexcept { return s_; }
  double cos() const noexcept { return c_; }
  // mean: cos and sin (cm, sm) of the heading plus h, from cos h and sin h: the mean heading of
  // a step that turns by 2h.
  void mean(double ch, double sh, double& cm, double& sm) const noexcept {
    cm = c_ * ch - s_ * sh;
    sm = s_ * ch + c_ * sh;
  }
  // finish: the step of mean (cm, sm) ended at heading theta (heading + 2h): rotate the mean once
  // more by h, or every resync_steps re-derive from theta.
  void finish(double theta, double cm, double sm, double ch, double sh) noexcept {
    if (++steps_ >= resync_steps_) {
      reset(theta);
    } else {
      c_ = cm * ch - sm * sh;
      s_ = sm * ch + cm * sh;
    }
  }

 private:
  double s_ = 0.0;  // sin(heading)
  double c_ = 1.0;  // cos(heading)
  std::uint32_t steps_ = 0;
  std::uint32_t resync_steps_;
};

// PoseIntegrator: exact-arc integration that carries sin and cos of the heading from tick to
// tick, so a tick with a small turn costs no trigonometric call at all.
class PoseIntegrator {
 public:
  PoseIntegrator() { reset(Pose2{}); }
  // reset: set the pose (e.g. at start or on a set-pose command).
  void reset(const Pose2& p) noexcept;
  // step: advance by wheel travels d_left, d_right [m] with wheelbase b [m].
  void step(double d_left, double d_right, double b) noexcept {
    step_arc(0.5 * (d_left + d_right), (d_right - d_left) / b);
  }
  // step_arc: advance along an arc of centre travel ds [m] and heading change dtheta [rad] (a
  // heading from elsewhere, e.g. the gyrodometry fusion; step() is step_arc of the wheels').
  void step_arc(double ds, double dtheta) noexcept;
  // step_arc_icr: step_arc of a body whose instantaneous centre of rotation lies x_icr [m] ahead
  // of the centre point, so that the centre slides sideways by -x_icr * dtheta [m] (x_icr != 0;
  // the tick keeps step_arc for the plain base).
  void step_arc_icr(double ds, double dtheta, double x_icr) noexcept;
  const Pose2& pose() const noexcept { return pose_; }
  double sin_theta() const noexcept { return heading_.sin(); }
  double cos_theta() const noexcept { return heading_.cos(); }

 private:
  // Re-derive sin/cos from theta every this many steps so that the rotated pair can never drift
  // from the cumulative heading by more than a few ulp.
  static constexpr std::uint32_t kResyncSteps = 1024;
  Pose2 pose_;
  HeadingRotor heading_{kResyncSteps};  // of pose_.theta
};

// Odometry: counts -> pose and velocity with the calibrated kinematics, and the pose's
// covariance under the Chong-Kleeman error model.
class Odometry {
 public:
  explicit Odometry(const Kinematics& k, const ErrorModelParams& error_model = {})
      : k_(k), cov_(error_model) {}
  // update: integrate the count deltas of one tick of length dt [s] (dt <= 0: velocity kept);
  // the pose only.
  void update(std::int64_t dn_left, std::int64_t dn_right, double dt) noexcept {
    if (k_.skid()) [[unlikely]] {
      update_skid(dn_left, dn_right, dt);
      return;
    }
    update_plain(dn_left, dn_right, dt);
  }
  // advance: update() and the covariance step of the same tick.
  void advance(std::int64_t dn_left, std::int64_t dn_right, double dt) noexcept {
    // The covariance needs the heading at the start of the tick; the integrator's cached sine
    // and cosine of it spare a trigonometric call.
    // A plain base tests one flag per tick and takes no sideways slide (its bits and cost kept).
    if (k_.skid()) [[unlikely]] {
      advance_skid(dn_left, dn_right, dt);
      return;
    }
    const double s0 = sin_theta(), c0 = cos_theta();
    update_plain(dn_left, dn_right, dt);
    // update's heading change is (d_R - d_L) / b: the covariance's phi, already divided.
    cov_.step_sc_phi(s0, c0, d_left_, d_right_, k_.wheelbase(), dth_);
  }
  // reset: set the pose, taken as exact (zero covariance); velocities and distance are kept.
  void reset(const Pose2& p) noexcept {
    integ_.reset(p);
    cov_.reset();
  }
  // restore: continue from a saved pose, covariance and path length [m] (a resumed state).
  void restore(const Pose2& p, const Cov3& cov, double distance) noexcept {
    integ_.reset(p);
    cov_.restore(cov);
    distance_ = distance;
  }
  // update_fused: the same with the heading changing by dtheta [rad] instead of
  // (d_R - d_L) / b and the centre travel by ds_correction [m] more than the wheels' mean (the
  // gyrodometry fusion's FusedTick::dtheta and ::ds); bit-identical to update() when dtheta is
  // odometry's own increment and ds_correction is 0.
  void update_fused(std::int64_t dn_left, std::int64_t dn_right, double dt, double dtheta,
                    double ds_correction) noexcept;
  // advance_travel: advance() from the tick's wheel travels d_l, d_r [m] that the caller has
  // already converted from counts (count x metres_per_count, Eq. 6.35: the same bits as
  // advance computes), so that a fused tick converts its counts once.
  void advance_travel(double d_l, double d_r, double dt) noexcept {
    if (k_.skid()) [[unlikely]] {
      advance_travel_skid(d_l, d_r, dt);
      return;
    }
    const double s0 = sin_theta(), c0 = cos_theta();
    update_travel_plain(d_l, d_r, dt);
    cov_.step_sc_phi(s0, c0, d_left_, d_right_, k_.wheelbase(), dth_);
  }
  // update_travel: update() from wheel travels d_l, d_r [m] (the pose only).
  void update_travel(double d_l, double d_r, double dt) noexcept {
    if (k_.skid()) [[unlikely]] {
      integrate_skid(d_l, d_r, 0.5 * (d_l + d_r), (d_r - d_l) / k_.wheelbase(), dt);
      return;
    }
    update_travel_plain(d_l, d_r, dt);
  }
  // advance_fused: from the wheel travels d_l, d_r [m] (as advance_travel), the heading changing
  // by dtheta [rad] and the centre travel by ds_correction [m] more than the wheels' mean (the
  // fusion's FusedTick), with the covariance step of the same tick: the wheels' arc when
  // gyro_heading is false (dtheta is then odometry's own), otherwise the gyro's heading noise
  // var_heading [rad^2] instead of the wheels' differential noise (propagate_gyro_arc).
  void advance_fused(double d_l, double d_r, double dt, double dtheta, double ds_correction,
                     bool gyro_heading, double var_heading) noexcept;
  // advance_slip: advance_fused of a tick inside a within-side slip interval: the wheels' travels
  // carry the extra variances var_left, var_right [m^2] (slip_travel_variance): added to the
  // wheels' noise (propagate_arc_slip), or, on a gyro tick, to the along-track variance only
  // (the heading is the gyro's). Without a gyro: dtheta = (d_r - d_l) / b, ds_correction 0.
  void advance_slip(double d_l, double d_r, double dt, double dtheta, double ds_correction,
                    bool gyro_heading, double var_heading, double var_left,
                    double var_right) noexcept;
  // flush_covariance: propagate the ticks the covariance still has merged
  // (ErrorModelParams::covariance_ticks > 1), so that covariance() is the pose's.
  void flush_covariance() noexcept { cov_.flush(); }
  // set_kinematics: swap in new calibration (e.g. after SIGHUP); the pose is kept.
  void set_kinematics(const Kinematics& k) noexcept { k_ = k; }

  const Kinematics& kinematics() const noexcept { return k_; }
  const Pose2& pose() const noexcept { return integ_.pose(); }
  double sin_theta() const noexcept { return integ_.sin_theta(); }  // sin of pose().theta
  double cos_theta() const noexcept { return integ_.cos_theta(); }  // cos of pose().theta
  double linear_velocity() const noexcept { return v_; }            // [m/s] of the centre point
  double angular_velocity() const noexcept { return omega_; }       // [rad/s]
  double distance() const noexcept { return distance_; }            // path length of the centre [m]
  double last_d_left() const noexcept { return d_left_; }    // wheel travel of the last tick [m]
  double last_d_right() const noexcept { return d_right_; }  // [m]
  // covariance: of (x, y, theta), row-major [m^2, m rad, rad^2], accumulated by advance(); with
  // covariance_ticks = n > 1 it is that of the pose up to n - 1 ticks ago.
  const Cov3& covariance() const noexcept { return cov_.cov(); }

 private:
  // update_plain, update_travel_plain: update() and update_travel() of a base without x_icr.
  void update_plain(std::int64_t dn_left, std::int64_t dn_right, double dt) noexcept;
  void update_travel_plain(double d_l, double d_r, double dt) noexcept;
  // update_skid, advance_skid, advance_travel_skid: update(), advance() and advance_travel()
  // with the sideways slide of x_icr != 0 (out of line: the plain tick stays as it was).
  void update_skid(std::int64_t dn_left, std::int64_t dn_right, double dt) noexcept;
  void advance_skid(std::int64_t dn_left, std::int64_t dn_right, double dt) noexcept;
  void advance_travel_skid(double d_l, double d_r, double dt) noexcept;
  // integrate: one tick of wheel travels d_l, d_r [m], centre travel ds [m] and heading change
  // dth [rad]; integrate_skid: the same with the kinematics' sideways slide -x_icr * dth.
  void integrate(double d_l, double d_r, double ds, double dth, double dt) noexcept;
  void integrate_skid(double d_l, double d_r, double ds, double dth, double dt) noexcept;
  // record: the tick's bookkeeping after its pose step (travels, distance, velocities).
  void record(double d_l, double d_r, double ds, double dth, double dt) noexcept;
  // step_covariance_icr: the covariance step of the last tick (started at heading s0, c0) for
  // x_icr != 0: the plain arc's (gyro_heading: the gyro's, var_heading [rad^2]) about the
  // instantaneous centre of rotation (PoseCovariance::shift_point).
  void step_covariance_icr(double s0, double c0, bool gyro_heading, double var_heading) noexcept;
  Kinematics k_;
  PoseCovariance cov_;
  PoseIntegrator integ_;
  double v_ = 0.0;
  double omega_ = 0.0;
  double distance_ = 0.0;
  double d_left_ = 0.0;
  double d_right_ = 0.0;
  double dth_ = 0.0;     // heading change of the last tick [rad]
  double dt_of_ = 0.0;   // the tick length [s] that inv_dt_ is the reciprocal of
  double inv_dt_ = 0.0;  // 1.0 / dt_of_ [1/s]
};

}  // namespace odo
