// Chong-Kleeman non-systematic odometry error model (Chong & Kleeman 1997, Sec. 4, Eq. 13-18):
// every wheel's travel d carries white noise of variance k^2 |d|, and the pose covariance of a
// constant-curvature arc has a closed form (the k -> infinity limit of Eq. 15/16). Because the
// closed form is that limit, it is consistent: one segment or the same path cut into any number
// of pieces gives the same covariance.
#pragma once

#include <array>
#include <cstdint>
#include <optional>

#include "odo/hal/field_range.hpp"
#include "odo/hal/result.hpp"

namespace odo {

// Covariance of (x, y, theta), row-major [m^2, m^2, m rad; ...; rad^2].
using Cov3 = std::array<double, 9>;

// Per-wheel noise coefficients: variance of a wheel's travel d is k^2 |d| [m^2].
struct ErrorModelParams {
  double k_left = 0.00040;   // k_L [m^(1/2)], the paper's fitted value
  double k_right = 0.00058;  // k_R [m^(1/2)]
  // Loop ticks merged into one covariance step (1: every tick). The closed form is consistent
  // (an arc cut into pieces gives the covariance of the whole), so a group of ticks taken as one
  // arc of their summed travels changes the covariance only by how much the group's curvature
  // varies; a fast loop (1 kHz on a microcontroller) saves the step's cost on all other ticks.
  std::uint32_t covariance_ticks = 1;
};

// Allowed range of k_L and k_R [m^(1/2)]: 0 (no noise) up to 0.1 (10 cm after 1 m).
inline constexpr double kErrorModelKMax = 0.1;
// Allowed range of covariance_ticks: 1 up to 100 (0.1 s of covariance lag at 1 kHz).
inline constexpr std::uint32_t kCovarianceTicksMax = 100;

// error_model_range: the first parameter that is not finite or not within its range (k_left,
// k_right: [0, kErrorModelKMax]; covariance_ticks: [1, kCovarianceTicksMax]), as data; nullopt
// when all are.
std::optional<FieldRange> error_model_range(const ErrorModelParams& k);
// check_error_model: the same as an error (message from range_message).
Status check_error_model(const ErrorModelParams& k);

// Covariance of the twist (v, omega) of one interval, row-major 2x2 [m^2/s^2, m rad/s^2;
// rad^2/s^2].
using Cov2 = std::array<double, 4>;

// TickMotion: what one loop tick measured, as the loop integrated it: each wheel's calibrated
// travel, the interval the travels cover and the wheelbase in use then; a tick whose heading
// increment was the gyro's (gyrodometry) carries the variance that increment has.
struct TickMotion {
  double d_left = 0.0;            // left wheel travel [m] (c_L applied)
  double d_right = 0.0;           // right wheel travel [m]
  double dt = 0.0;                // interval between the tick's sample and the previous [s]
  double wheelbase = 0.0;         // b in use for this tick [m]
  bool gyro_heading = false;      // the heading increment (so omega) is the gyro's
  double gyro_var_heading = 0.0;  // its variance [rad^2] when gyro_heading
};

// twist_covariance: the covariance of (v, omega) = ((d_L + d_R) / (2 dt), dtheta / dt) of one
// tick, from the wheels' variances k^2 |d| (Chong & Kleeman Eq. 4); on a gyro tick omega's
// variance is the gyro's increment's over dt^2, independent of the wheels. Zero for dt <= 0 or
// b <= 0 (nothing measured).
Cov2 twist_covariance(const TickMotion& m, const ErrorModelParams& k) noexcept;

// ArcTerms: the shape integrals of one arc of heading change phi = (d_R - d_L) / b, each
// int_0^1 ... du along the arc parameter u (see error_model.cpp for the definitions).
struct ArcTerms {
  double i_c, i_s;          // int cos(phi u), int sin(phi u)
  double i_cc, i_ss, i_cs;  // int cos^2, sin^2, cos sin
  double j_x, j_y;          // int X^, int Y^ (remaining displacement to the end, per metre)
  double j_xx, j_yy, j_xy;  // int X^2, Y^2, X Y
  double j_cx, j_cy;        // int cos X^, cos Y^
  double j_sx, j_sy;        // int sin X^, sin Y^
};

// arc_terms: the integrals above for any phi [rad]; Taylor series below |phi| = 1, closed forms
// above, so no term loses more than a few ulp to cancellation and none is NaN or infinite.
ArcTerms arc_terms(double phi) noexcept;

// arc_input_covariance: Cov(U) of Eq. 16/17, the covariance that one arc with wheel travels
// d_left, d_right [m] adds, expressed in the frame of the arc's start pose (heading 0), for a
// base with wheelbase b [m].
Cov3 arc_input_covariance(double d_left, double d_right, double b,
                          const ErrorModelParams& k) noexcept;

// propagate_arc: cov <- F cov F^T + R Cov(U) R^T for an arc starting at heading theta0 [rad],
// with F the state Jacobian of the arc (Eq. 16, first term) and R the rotation by theta0.
void propagate_arc(Cov3& cov, double theta0, double d_left, double d_right, double b,
                   const ErrorModelParams& k) noexcept;

// propagate_arc: the same with the start heading given by its sine and cosine (the integrator
// keeps them, so a tick needs no trigonometric call).
void propagate_arc(Cov3& cov, double sin_theta0, double cos_theta0, double d_left, double d_right,
                   double b, const ErrorModelParams& k) noexcept;

// propagate_arc_known: the same for a caller that has phi = (d_right - d_left) / b [rad] and
// inv_b = 1.0 / b [1/m] at hand (computed exactly so: the same bits, two divisions fewer, which
// a Cortex-M4 does in software at ~570 instructions each).
void propagate_arc_known(Cov3& cov, double sin_theta0, double cos_theta0, double d_left,
                         double d_right, double b, double inv_b, double phi,
                         const ErrorModelParams& k) noexcept;

// propagate_arc_slip: propagate_arc of a tick whose wheel travels carry, besides the
// Chong-Kleeman noise k^2 |d|, the extra variances var_left, var_right [m^2] of a within-side
// slip (slip_travel_variance), spread along the arc as the wheel noise is.
void propagate_arc_slip(Cov3& cov, double sin_theta0, double cos_theta0, double d_left,
                        double d_right, double b, const ErrorModelParams& k, double var_left,
                        double var_right) noexcept;

// slip_travel_variance: the extra variance [m^2] of a side's travel on one tick of a slip
// interval (the wheels of the side disagree, hal/side_wheels.hpp): with S the interval's spread
// so far [m] (updated here) and `spread` this tick's [m, >= 0], S'^2 - S^2 (derivation in
// error_model.cpp).
inline double slip_travel_variance(double& interval_spread, double spread) noexcept {
  const double before = interval_spread;
  interval_spread += spread;
  return spread * (2.0 * before + spread);
}

// propagate_local: cov <- F cov F^T + R q R^T for any step whose displacement in the frame of
// its start heading (sin_theta0, cos_theta0) is (lx, ly) [m] and whose input covariance in that
// frame is q (e.g. a tick whose heading came from a gyro, odometry/gyrodometry.hpp).
void propagate_local(Cov3& cov, double sin_theta0, double cos_theta0, double lx, double ly,
                     const Cov3& q) noexcept;

// PoseCovariance: the running covariance of the integrated pose; starts at zero. With
// covariance_ticks = n > 1 the ticks' arcs are summed and propagated as one arc every n ticks
// (and before anything that must follow them: a gyro tick, a wheel that reverses, a new
// wheelbase); cov() then lags the pose by at most n - 1 ticks.
class PoseCovariance {
 public:
  explicit PoseCovariance(const ErrorModelParams& k = {}) : k_(k) {}
  // reset: zero covariance (a pose that was just set is taken as exact).
  void reset() noexcept {
    cov_ = {};
    group_ = {};
  }
  // restore: continue from a covariance saved earlier (a resumed state record).
  void restore(const Cov3& cov) noexcept {
    cov_ = cov;
    group_ = {};
  }
  // step: add one tick's arc; theta0 is the heading at the start of the tick [rad], d_left and
  // d_right the wheel travels of the tick [m], b the wheelbase [m].
  void step(double theta0, double d_left, double d_right, double b) noexcept {
    flush();
    propagate_arc(cov_, theta0, d_left, d_right, b, k_);
  }
  // step_sc: the same with the start heading as sin and cos (no trigonometric call).
  void step_sc(double sin_theta0, double cos_theta0, double d_left, double d_right,
               double b) noexcept {
    flush();
    propagate_arc(cov_, sin_theta0, cos_theta0, d_left, d_right, b, k_);
  }
  // step_sc_phi: step_sc of a tick whose phi = (d_right - d_left) / b [rad] the caller has
  // computed (the pose step's heading change); 1 / b is kept from the last tick's b. Merged
  // into groups of covariance_ticks ticks.
  void step_sc_phi(double sin_theta0, double cos_theta0, double d_left, double d_right, double b,
                   double phi) noexcept {
    if (k_.covariance_ticks > 1) {
      merge(sin_theta0, cos_theta0, d_left, d_right, b, phi);
      return;
    }
    propagate_known(sin_theta0, cos_theta0, d_left, d_right, b, phi);
  }
  // step_gyro_sc: a tick whose heading change dtheta [rad] came from the gyro, with heading
  // variance var_heading [rad^2] (gyrodometry.hpp propagate_gyro_arc; defined there);
  // extra_var_ds [m^2] adds to the along-track variance (a slip tick's, (var_L + var_R) / 4).
  void step_gyro_sc(double sin_theta0, double cos_theta0, double d_left, double d_right,
                    double dtheta, double var_heading, double extra_var_ds = 0.0) noexcept;
  // step_slip_sc: step_sc of a tick whose wheel travels carry the extra variances var_left,
  // var_right [m^2] of a within-side slip (propagate_arc_slip).
  void step_slip_sc(double sin_theta0, double cos_theta0, double d_left, double d_right, double b,
                    double var_left, double var_right) noexcept {
    flush();
    propagate_arc_slip(cov_, sin_theta0, cos_theta0, d_left, d_right, b, k_, var_left, var_right);
  }
  // shift_point: flush, then make cov() that of the pose of the point e [m] ahead of the one it
  // was of, on the body's x axis, at heading (sin_theta, cos_theta) (a skid-steer base's
  // instantaneous centre of rotation, Odometry::advance).
  void shift_point(double sin_theta, double cos_theta, double e) noexcept;
  // flush: propagate the ticks merged so far (none: nothing), so that cov() includes them.
  void flush() noexcept;
  // pending_ticks: ticks merged but not yet in cov() (0 with covariance_ticks = 1).
  std::uint32_t pending_ticks() const noexcept { return group_.ticks; }
  void set_params(const ErrorModelParams& k) noexcept {
    flush();
    k_ = k;
  }
  const ErrorModelParams& params() const noexcept { return k_; }
  const Cov3& cov() const noexcept { return cov_; }

 private:
  // Group: the ticks merged since the last covariance step.
  struct Group {
    std::uint32_t ticks = 0;
    double sin0 = 0.0, cos0 = 1.0;  // of the heading at the start of the group's first tick
    double d_left = 0.0, d_right = 0.0, phi = 0.0;  // summed [m, m, rad]
    double b = 0.0;                                 // wheelbase of every tick in it [m]
  };
  // merge: add one tick to the group, propagating the group when it is full.
  void merge(double sin_theta0, double cos_theta0, double d_left, double d_right, double b,
             double phi) noexcept;
  // propagate_known: one arc with phi known, 1 / b kept for the last b.
  void propagate_known(double sin_theta0, double cos_theta0, double d_left, double d_right,
                       double b, double phi) noexcept {
    if (b != inv_b_of_) {  // the wheelbase changes only with a new calibration
      inv_b_of_ = b;
      inv_b_ = 1.0 / b;
    }
    propagate_arc_known(cov_, sin_theta0, cos_theta0, d_left, d_right, b, inv_b_, phi, k_);
  }
  ErrorModelParams k_;
  Cov3 cov_{};
  Group group_{};
  double inv_b_of_ = 0.0;  // the wheelbase [m] that inv_b_ is the reciprocal of
  double inv_b_ = 0.0;     // 1.0 / inv_b_of_ [1/m]
};

}  // namespace odo
