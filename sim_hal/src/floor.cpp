#include "odo/sim/floor.hpp"

#include <algorithm>
#include <cmath>

namespace odo::sim {

double bump_travel_loss(double r, double h) noexcept {
  if (!(h > 0.0) || !(h < r)) return 0.0;
  // The wheel pivots about the step's edge: the encoder sees the arc r * acos(1 - h/r), the
  // ground only the chord's horizontal part; twice, up and down.
  return 2.0 * (r * std::acos(1.0 - h / r) - std::sqrt(2.0 * r * h - h * h));
}

UmbmarkFloor::UmbmarkFloor(const Options& o, std::uint64_t seed) noexcept : o_(o), rng_(seed) {
  to_next_ = {next_spacing(), next_spacing()};
}

double UmbmarkFloor::next_spacing() noexcept {
  // "Approximately every 2 cm": uniform in [0.5, 1.5] times the mean spacing.
  return o_.roughness_spacing * (0.5 + unit_(rng_));
}

void UmbmarkFloor::perturb(double& d_left, double& d_right) noexcept {
  // The first leg ends at the first on-the-spot turn (wheels moving in opposite directions).
  if (d_left * d_right < 0.0) first_leg_ = false;
  if (first_leg_ && bumps_done_ < o_.bumps) {
    leg_travel_ += 0.5 * (d_left + d_right);
    // Bump k sits at (k + 1/2) L / n: evenly spread over the leg, as the report asks.
    while (bumps_done_ < o_.bumps && leg_travel_ >= (bumps_done_ + 0.5) * o_.first_leg / o_.bumps) {
      pending_[o_.bumps_under_left ? 0 : 1] += o_.bump_loss;
      ++bumps_done_;
    }
  }
  std::array<double*, 2> d{&d_left, &d_right};
  for (int w = 0; w < 2; ++w) {
    if (o_.roughness_height > 0.0) {
      to_next_[w] -= std::fabs(*d[w]);
      while (to_next_[w] <= 0.0) {
        pending_[w] += bump_travel_loss(o_.wheel_radius, o_.roughness_height * unit_(rng_));
        to_next_[w] += next_spacing();
      }
    }
    // A loss larger than this step's travel is carried into the next steps, never reverses it.
    const double apply = std::min(pending_[w], std::fabs(*d[w]));
    *d[w] -= std::copysign(apply, *d[w]);
    pending_[w] -= apply;
  }
}

}  // namespace odo::sim
