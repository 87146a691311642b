#include "odo/odometry/pose.hpp"

#include <cmath>
#include <numbers>

namespace odo {

Pose2 arc_step(const Pose2& p, double d_left, double d_right, double b) noexcept {
  // On an arc of chord angle dtheta the centre moves along the chord of length
  // ds * sinc(dtheta/2), pointing at the mean heading theta + dtheta/2.
  const double ds = 0.5 * (d_left + d_right);
  const double dth = (d_right - d_left) / b;
  const HalfAngle h = half_angle(0.5 * dth);
  const double chord = ds * h.sinc;
  const double mid = p.theta + 0.5 * dth;
  return {p.x + chord * std::cos(mid), p.y + chord * std::sin(mid), p.theta + dth};
}

Pose2 arc_step_icr(const Pose2& p, double d_left, double d_right, double b, double x_icr) noexcept {
  // PoseIntegrator::step_arc_icr derives the chord pair (ds, -x_icr dtheta) * sinc(dtheta/2).
  const double dth = (d_right - d_left) / b;
  const HalfAngle h = half_angle(0.5 * dth);
  const double along = 0.5 * (d_left + d_right) * h.sinc;
  const double across = -x_icr * dth * h.sinc;
  const double mid = p.theta + 0.5 * dth;
  const double cm = std::cos(mid), sm = std::sin(mid);
  return {p.x + along * cm - across * sm, p.y + along * sm + across * cm, p.theta + dth};
}

Pose2 report_step(const Pose2& p, double d_left, double d_right, double b) noexcept {
  const double du = 0.5 * (d_right + d_left);                     // Eq. 2.3
  const double th = p.theta + (d_right - d_left) / b;             // Eq. 2.4, 2.5
  return {p.x + du * std::cos(th), p.y + du * std::sin(th), th};  // Eq. 2.6a/b
}

void PoseIntegrator::reset(const Pose2& p) noexcept {
  pose_ = p;
  heading_.reset(p.theta);
}

void PoseIntegrator::step_arc(double ds, double dth) noexcept {
  const HalfAngle h = half_angle(0.5 * dth);
  double cm = 0.0, sm = 0.0;  // of the mean heading theta + h
  heading_.mean(h.c, h.s, cm, sm);
  const double chord = ds * h.sinc;
  pose_.x += chord * cm;
  pose_.y += chord * sm;
  pose_.theta += dth;
  heading_.finish(pose_.theta, cm, sm, h.c, h.s);
}

void PoseIntegrator::step_arc_icr(double ds, double dth, double x_icr) noexcept {
  // Over a tick of length T the body twist is constant: forward v = ds/T, sideways
  // vy = -x_icr * omega (the body turns about the point x_icr ahead of its centre), omega = dth/T.
  // In the odometry frame the centre moves by the integral of R(theta0 + omega t) (v, vy) over
  // [0, T], and the integral of R(theta0 + omega t) is T sinc(dth/2) R(theta0 + dth/2) (e.g.
  // (sin(theta0 + dth) - sin theta0) / omega = 2 cos(theta0 + dth/2) sin(dth/2) / omega). So the
  // step is the body-frame pair (ds, -x_icr dth) shortened by sinc(dth/2) and rotated to the mean
  // heading: step_arc's chord plus a sideways chord, with the same half-angle and rotor.
  const HalfAngle h = half_angle(0.5 * dth);
  double cm = 0.0, sm = 0.0;
  heading_.mean(h.c, h.s, cm, sm);
  const double along = ds * h.sinc;
  const double across = -x_icr * dth * h.sinc;
  pose_.x += along * cm - across * sm;
  pose_.y += along * sm + across * cm;
  pose_.theta += dth;
  heading_.finish(pose_.theta, cm, sm, h.c, h.s);
}

// flatten: the integrator's step inlined into the tick's pose update (a call would spill the
// values the update still needs around it; other callers keep the out-of-line step_arc).
[[gnu::flatten]] void Odometry::update_plain(std::int64_t dn_left, std::int64_t dn_right,
                                             double dt) noexcept {
  const double d_l = static_cast<double>(dn_left) * k_.metres_per_count_left();  // Eq. 6.35
  const double d_r = static_cast<double>(dn_right) * k_.metres_per_count_right();
  // update_fused() with ds_correction 0 adds 0.0 to the mean travel, which changes no bits here:
  // x + 0.0 == x except for x = -0.0, and the mean is never -0.0 (a count of 0 gives +0.0, a
  // finite x + (-x) is +0.0).
  integrate(d_l, d_r, 0.5 * (d_l + d_r), (d_r - d_l) / k_.wheelbase(), dt);
}

[[gnu::flatten]] void Odometry::update_travel_plain(double d_l, double d_r, double dt) noexcept {
  integrate(d_l, d_r, 0.5 * (d_l + d_r), (d_r - d_l) / k_.wheelbase(), dt);
}

void Odometry::update_skid(std::int64_t dn_left, std::int64_t dn_right, double dt) noexcept {
  const double d_l = static_cast<double>(dn_left) * k_.metres_per_count_left();
  const double d_r = static_cast<double>(dn_right) * k_.metres_per_count_right();
  integrate_skid(d_l, d_r, 0.5 * (d_l + d_r), (d_r - d_l) / k_.wheelbase(), dt);
}

void Odometry::advance_skid(std::int64_t dn_left, std::int64_t dn_right, double dt) noexcept {
  const double s0 = sin_theta(), c0 = cos_theta();
  update_skid(dn_left, dn_right, dt);
  step_covariance_icr(s0, c0, false, 0.0);
}

void Odometry::advance_travel_skid(double d_l, double d_r, double dt) noexcept {
  const double s0 = sin_theta(), c0 = cos_theta();
  integrate_skid(d_l, d_r, 0.5 * (d_l + d_r), (d_r - d_l) / k_.wheelbase(), dt);
  step_covariance_icr(s0, c0, false, 0.0);
}

void Odometry::update_fused(std::int64_t dn_left, std::int64_t dn_right, double dt, double dtheta,
                            double ds_correction) noexcept {
  const double d_l = static_cast<double>(dn_left) * k_.metres_per_count_left();
  const double d_r = static_cast<double>(dn_right) * k_.metres_per_count_right();
  if (k_.skid()) [[unlikely]] {
    integrate_skid(d_l, d_r, 0.5 * (d_l + d_r) + ds_correction, dtheta, dt);
    return;
  }
  integrate(d_l, d_r, 0.5 * (d_l + d_r) + ds_correction, dtheta, dt);
}

void Odometry::advance_fused(double d_l, double d_r, double dt, double dtheta, double ds_correction,
                             bool gyro_heading, double var_heading) noexcept {
  const double s0 = sin_theta(), c0 = cos_theta();
  if (k_.skid()) [[unlikely]] {
    integrate_skid(d_l, d_r, 0.5 * (d_l + d_r) + ds_correction, dtheta, dt);
    step_covariance_icr(s0, c0, gyro_heading, var_heading);
    return;
  }
  integrate(d_l, d_r, 0.5 * (d_l + d_r) + ds_correction, dtheta, dt);
  if (gyro_heading) {
    cov_.step_gyro_sc(s0, c0, d_left_, d_right_, dtheta, var_heading);
  } else {
    cov_.step_sc(s0, c0, d_left_, d_right_, k_.wheelbase());
  }
}

void Odometry::advance_slip(double d_l, double d_r, double dt, double dtheta, double ds_correction,
                            bool gyro_heading, double var_heading, double var_left,
                            double var_right) noexcept {
  const double s0 = sin_theta(), c0 = cos_theta();
  // A skid-steer base slides about its ICR here too: the slip's variances go into the plain step
  // of the ICR's pose, between the two shifts of step_covariance_icr.
  const bool skid = k_.skid();
  if (skid) {
    integrate_skid(d_l, d_r, 0.5 * (d_l + d_r) + ds_correction, dtheta, dt);
    cov_.shift_point(s0, c0, k_.x_icr());
  } else {
    integrate(d_l, d_r, 0.5 * (d_l + d_r) + ds_correction, dtheta, dt);
  }
  if (gyro_heading) {
    cov_.step_gyro_sc(s0, c0, d_left_, d_right_, dtheta, var_heading,
                      0.25 * (var_left + var_right));
  } else {
    cov_.step_slip_sc(s0, c0, d_left_, d_right_, k_.wheelbase(), var_left, var_right);
  }
  if (skid) cov_.shift_point(sin_theta(), cos_theta(), -k_.x_icr());
}

void Odometry::step_covariance_icr(double s0, double c0, bool gyro_heading,
                                   double var_heading) noexcept {
  // The centre's covariance to that of the instantaneous centre of rotation, which moves as a
  // plain base's centre, one plain step, and back at the tick's end heading.
  const double x = k_.x_icr();
  cov_.shift_point(s0, c0, x);
  if (gyro_heading) {
    cov_.step_gyro_sc(s0, c0, d_left_, d_right_, dth_, var_heading);
  } else {
    cov_.step_sc_phi(s0, c0, d_left_, d_right_, k_.wheelbase(), dth_);
  }
  cov_.shift_point(sin_theta(), cos_theta(), -x);
}

void Odometry::integrate(double d_l, double d_r, double ds, double dth, double dt) noexcept {
  integ_.step_arc(ds, dth);
  record(d_l, d_r, ds, dth, dt);
}

void Odometry::integrate_skid(double d_l, double d_r, double ds, double dth, double dt) noexcept {
  integ_.step_arc_icr(ds, dth, k_.x_icr());
  record(d_l, d_r, ds, dth, dt);
}

void Odometry::record(double d_l, double d_r, double ds, double dth, double dt) noexcept {
  d_left_ = d_l;
  d_right_ = d_r;
  dth_ = dth;
  distance_ += std::fabs(ds);
  if (dt > 0.0) {
    // A fixed-rate loop's ticks have one length: its reciprocal is divided once (a division is
    // ~570 instructions on a Cortex-M4, the same bits either way).
    if (dt != dt_of_) {
      dt_of_ = dt;
      inv_dt_ = 1.0 / dt;
    }
    v_ = ds * inv_dt_;
    omega_ = dth * inv_dt_;
  }
}

}  // namespace odo
