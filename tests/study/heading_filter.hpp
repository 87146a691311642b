// EXPERIMENTAL (issue 16 exploration; tests/study only, not wired into the loop): a continuously
// fusing heading filter. On the extended UMBmark it does WORSE than gyrodometry (BENCHMARKS.md
// "Heading fusion ceilings"): learning the gyro's bias and scale from odometry imports
// odometry's calibration residual. Kept as the record of what was tried. A four-state Kalman filter
// over x = (theta, b, s, e):
//   theta  the true heading [rad], propagated with the gyro's increment u = rate * dt:
//          theta' = theta + u - b dt - s u + w_g,  var(w_g) = N^2 dt (angle random walk);
//   b      the gyro's bias [rad/s], a random walk of K^2 dt;
//   s      the gyro's scale-factor error (u = (1 + s) true increment + ...), constant;
//   e      odometry's heading error [rad], a random walk of V per tick, V = (k_L^2 |d_L| +
//          k_R^2 |d_R|) / b^2 (Chong & Kleeman), or the online estimate q_hat |d| (see below).
// Measurement every tick: odometry's cumulative heading z = theta + e (+ its count quantisation,
// variance r). Both sensors are relative; the filter splits every disagreement between the two by
// their variances, so the heading increment it returns is the inverse-variance weighted one, and
// the long-run mean of the disagreement is the gyro's bias (at standstill V = 0 and the filter
// learns b exactly as the standstill average does). Pure math: inputs and time are arguments; no
// allocation, no exception.
//
// Online odometry noise (adaptive = true): over windows of `window` seconds of travel the
// disagreement D = sum (u_corrected - dtheta_odo) has variance N^2 T + q |d|; q_hat is the
// running mean of max(0, D^2 - N^2 T) / |d| (windows with |d| > 0), clamped to [0, q_max].
#pragma once

#include <cstdint>

namespace odo {

struct HeadingFilterParams {
  double rate_noise_density = 2.443e-4;  // N [rad/s/sqrt(Hz)]
  double bias_walk = 9.7e-7;             // K [rad/s/sqrt(s)]
  double bias_sigma0 = 0.035;            // prior std of the bias [rad/s] (2 deg/s)
  double scale_sigma0 = 0.01;            // prior std of the scale-factor error
  double k_left = 0.00040;               // Chong-Kleeman k_L [m^(1/2)] (adaptive = false)
  double k_right = 0.00058;              // k_R [m^(1/2)]
  double wheelbase = 0.34;               // b [m] (Chong-Kleeman variance of the heading)
  double quantum = 8.46e-5;              // q = (m_L + m_R)/b [rad]: one count on each wheel
  bool adaptive = false;                 // estimate odometry's noise online (see top)
  double window = 1.0;                   // [s] of the adaptive windows
  double q_max = 1e-5;                   // clamp of q_hat [rad^2/m]
  double q_init = 0.0;                   // q_hat before the first window [rad^2/m]
};

struct HeadingFilterInput {
  double dt = 0.0;             // tick length [s]
  double d_left = 0.0;         // wheel travels of the tick [m]
  double d_right = 0.0;        // [m]
  double dtheta_odo = 0.0;     // odometry's (or gyrodometry's) heading increment [rad]
  double rate = 0.0;           // the gyro's raw mean rate over the tick [rad/s]
  bool rate_ok = false;        // the gyro reading is usable
  double extra_var_odo = 0.0;  // extra variance of this tick's dtheta_odo [rad^2]
};

class HeadingFilter {
 public:
  explicit HeadingFilter(const HeadingFilterParams& p) noexcept;
  // step: one tick; returns the heading increment to integrate [rad].
  double step(const HeadingFilterInput& in) noexcept;
  double heading() const noexcept { return x_[0]; }  // [rad]
  double bias() const noexcept { return x_[1]; }     // [rad/s]
  double scale_error() const noexcept { return x_[2]; }
  double q_hat() const noexcept { return q_hat_; }  // [rad^2/m]

 private:
  void predict(double u, double dt, double v_odo) noexcept;
  void update(double z) noexcept;
  void adapt(const HeadingFilterInput& in, double u) noexcept;

  HeadingFilterParams p_;
  double x_[4] = {0.0, 0.0, 0.0, 0.0};
  double P_[4][4] = {};
  double z_ = 0.0;  // odometry's cumulative heading [rad]
  // adaptive windows
  double win_t_ = 0.0, win_d_ = 0.0, win_err_ = 0.0;
  double q_sum_ = 0.0, q_n_ = 0.0, q_hat_ = 0.0;
};

}  // namespace odo
