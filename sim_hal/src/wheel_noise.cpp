#include "odo/sim/wheel_noise.hpp"

#include <cmath>

namespace odo::sim {

WheelNoise::WheelNoise(double k_left, double k_right, std::uint64_t seed) noexcept
    : k_left_(k_left), k_right_(k_right), rng_(seed) {}

void WheelNoise::reseed(std::uint64_t seed) noexcept {
  rng_.seed(seed);
  normal_.reset();
}

void WheelNoise::perturb(double& d_left, double& d_right) noexcept {
  // Standard deviation k sqrt(|d|): the variances of consecutive steps add up to k^2 |total|.
  const double n_l = normal_(rng_), n_r = normal_(rng_);
  d_left += k_left_ * std::sqrt(std::fabs(d_left)) * n_l;
  d_right += k_right_ * std::sqrt(std::fabs(d_right)) * n_r;
}

}  // namespace odo::sim
