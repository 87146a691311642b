#include "heading_filter.hpp"

#include <algorithm>
#include <cmath>

namespace odo {

HeadingFilter::HeadingFilter(const HeadingFilterParams& p) noexcept : p_(p) {
  // The start pose is exact (theta = e = 0); bias and scale are unknown within their priors.
  P_[1][1] = p.bias_sigma0 * p.bias_sigma0;
  P_[2][2] = p.scale_sigma0 * p.scale_sigma0;
  q_hat_ = p.q_init;
}

void HeadingFilter::predict(double u, double dt, double v_odo) noexcept {
  // theta' = theta + u - b dt - s u: F = I except F[0][1] = -dt, F[0][2] = -u.
  x_[0] += u - x_[1] * dt - x_[2] * u;
  const double f1 = -dt, f2 = -u;
  // P' = F P F^T: row 0 becomes row0 + f1 row1 + f2 row2, then the same for column 0.
  for (int j = 0; j < 4; ++j) P_[0][j] += f1 * P_[1][j] + f2 * P_[2][j];
  for (int i = 0; i < 4; ++i) P_[i][0] += f1 * P_[i][1] + f2 * P_[i][2];
  const double n2 = p_.rate_noise_density * p_.rate_noise_density;
  P_[0][0] += n2 * dt;
  P_[1][1] += p_.bias_walk * p_.bias_walk * dt;
  P_[3][3] += v_odo;
}

void HeadingFilter::update(double z) noexcept {
  // H = [1 0 0 1]: the innovation variance and gain from columns 0 and 3.
  const double r = p_.quantum * p_.quantum / 6.0 + 1e-18;
  double ph[4];
  for (int i = 0; i < 4; ++i) ph[i] = P_[i][0] + P_[i][3];
  const double s = ph[0] + ph[3] + r;
  const double innov = z - (x_[0] + x_[3]);
  double k[4];
  for (int i = 0; i < 4; ++i) k[i] = ph[i] / s;
  for (int i = 0; i < 4; ++i) x_[i] += k[i] * innov;
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) P_[i][j] -= k[i] * ph[j];
  // Keep P symmetric against rounding.
  for (int i = 0; i < 4; ++i)
    for (int j = i + 1; j < 4; ++j) P_[i][j] = P_[j][i] = 0.5 * (P_[i][j] + P_[j][i]);
}

void HeadingFilter::adapt(const HeadingFilterInput& in, double u) noexcept {
  // The disagreement of a window: the gyro's increment corrected with the current estimates
  // minus odometry's. Its variance is N^2 T + q |d|; what exceeds N^2 T is odometry's.
  win_err_ += (u - x_[1] * in.dt) * (1.0 - x_[2]) - in.dtheta_odo;
  win_t_ += in.dt;
  win_d_ += std::fabs(in.d_left) + std::fabs(in.d_right);
  if (win_t_ < p_.window) return;
  if (win_d_ > 0.0) {
    const double n2 = p_.rate_noise_density * p_.rate_noise_density;
    const double q = std::max(0.0, win_err_ * win_err_ - n2 * win_t_) / win_d_;
    q_sum_ += q;
    q_n_ += 1.0;
    q_hat_ = std::min(p_.q_max, q_sum_ / q_n_);
  }
  win_t_ = win_d_ = win_err_ = 0.0;
}

double HeadingFilter::step(const HeadingFilterInput& in) noexcept {
  const double before = x_[0];
  const double dt = in.dt > 0.0 ? in.dt : 0.0;
  z_ += in.dtheta_odo;
  if (!in.rate_ok || !std::isfinite(in.rate)) {
    // No gyro: odometry's increment, and the filter's heading follows it.
    x_[0] += in.dtheta_odo;
    return in.dtheta_odo;
  }
  const double u = in.rate * dt;
  double v_odo;
  if (p_.adaptive) {
    adapt(in, u);
    v_odo = q_hat_ * (std::fabs(in.d_left) + std::fabs(in.d_right));
  } else {
    // Chong-Kleeman: the wheel variances k^2 |d| over b^2, with b from the increment.
    v_odo = (p_.k_left * p_.k_left * std::fabs(in.d_left) +
             p_.k_right * p_.k_right * std::fabs(in.d_right)) /
            (p_.wheelbase * p_.wheelbase);
  }
  predict(u, dt, v_odo + in.extra_var_odo);
  update(z_);
  return x_[0] - before;
}

}  // namespace odo
