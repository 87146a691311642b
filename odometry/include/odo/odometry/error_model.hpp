// Chong-Kleeman non-systematic odometry error model (Chong & Kleeman 1997, Sec. 4, Eq. 13-18):
// every wheel's travel d carries white noise of variance k^2 |d|, and the pose covariance of a
// constant-curvature arc has a closed form (the k -> infinity limit of Eq. 15/16). Because the
// closed form is that limit, it is consistent: one segment or the same path cut into any number
// of pieces gives the same covariance.
#pragma once

#include <array>
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
};

// Allowed range of k_L and k_R [m^(1/2)]: 0 (no noise) up to 0.1 (10 cm after 1 m).
inline constexpr double kErrorModelKMax = 0.1;

// error_model_range: the first coefficient that is not finite or not within
// [0, kErrorModelKMax], as data (field "k_left" or "k_right"); nullopt when both are.
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

// propagate_local: cov <- F cov F^T + R q R^T for any step whose displacement in the frame of
// its start heading (sin_theta0, cos_theta0) is (lx, ly) [m] and whose input covariance in that
// frame is q (e.g. a tick whose heading came from a gyro, odometry/gyrodometry.hpp).
void propagate_local(Cov3& cov, double sin_theta0, double cos_theta0, double lx, double ly,
                     const Cov3& q) noexcept;

// PoseCovariance: the running covariance of the integrated pose; starts at zero.
class PoseCovariance {
 public:
  explicit PoseCovariance(const ErrorModelParams& k = {}) : k_(k) {}
  // reset: zero covariance (a pose that was just set is taken as exact).
  void reset() noexcept { cov_ = {}; }
  // restore: continue from a covariance saved earlier (a resumed state record).
  void restore(const Cov3& cov) noexcept { cov_ = cov; }
  // step: add one tick's arc; theta0 is the heading at the start of the tick [rad], d_left and
  // d_right the wheel travels of the tick [m], b the wheelbase [m].
  void step(double theta0, double d_left, double d_right, double b) noexcept {
    propagate_arc(cov_, theta0, d_left, d_right, b, k_);
  }
  // step_sc: the same with the start heading as sin and cos (no trigonometric call).
  void step_sc(double sin_theta0, double cos_theta0, double d_left, double d_right,
               double b) noexcept {
    propagate_arc(cov_, sin_theta0, cos_theta0, d_left, d_right, b, k_);
  }
  // step_gyro_sc: a tick whose heading change dtheta [rad] came from the gyro, with heading
  // variance var_heading [rad^2] (gyrodometry.hpp propagate_gyro_arc; defined there).
  void step_gyro_sc(double sin_theta0, double cos_theta0, double d_left, double d_right,
                    double dtheta, double var_heading) noexcept;
  void set_params(const ErrorModelParams& k) noexcept { k_ = k; }
  const ErrorModelParams& params() const noexcept { return k_; }
  const Cov3& cov() const noexcept { return cov_; }

 private:
  ErrorModelParams k_;
  Cov3 cov_{};
};

}  // namespace odo
