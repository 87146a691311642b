// WheelNoise: the non-systematic error of Chong & Kleeman (Eq. 4) as a simulated fault: every
// step's ground travel d of a wheel gets independent Gaussian noise of variance k^2 |d|, so the
// noise of a whole path does not depend on how the simulation slices it into steps.
#pragma once

#include <cstdint>
#include <random>

#include "odo/sim/robot.hpp"

namespace odo::sim {

class WheelNoise final : public TravelPerturbation {
 public:
  // k_left, k_right [m^(1/2)]; seed selects the random sequence (runs are repeatable).
  WheelNoise(double k_left, double k_right, std::uint64_t seed) noexcept;
  // reseed: restart the sequence for another run.
  void reseed(std::uint64_t seed) noexcept;
  void perturb(double& d_left, double& d_right) noexcept override;

 private:
  double k_left_, k_right_;
  std::mt19937_64 rng_;
  std::normal_distribution<double> normal_{0.0, 1.0};
};

}  // namespace odo::sim
