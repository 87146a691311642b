// UmbmarkFloor: the floor of the UMBmark report's SET simulation (Sec. 4.6.2) as a simulated
// fault: random small bumps under both wheels (floor roughness) and, for the extended UMBmark,
// evenly spaced bumps under the inside wheel on the first leg. A wheel crossing a bump turns
// further than its horizontal travel, so the encoder over-counts: the step's ground travel is
// reduced by the bump's travel loss (Borenstein 1994b: Delta D = 2 (D_meas - D_hor)).
#pragma once

#include <array>
#include <cstdint>
#include <random>

#include "odo/sim/robot.hpp"

namespace odo::sim {

// bump_travel_loss: Delta D [m] of a rigid wheel of radius r [m] rolling up and down a step of
// height h [m] (0 <= h < r): 2 (r acos(1 - h/r) - sqrt(2 r h - h^2)).
double bump_travel_loss(double wheel_radius, double height) noexcept;

class UmbmarkFloor final : public TravelPerturbation {
 public:
  struct Options {
    double wheel_radius = 0.075;      // [m], for the roughness bumps' travel loss
    double roughness_height = 0.0;    // bump heights uniform in [0, this] [m]; 0: smooth
    double roughness_spacing = 0.02;  // mean distance between bumps under a wheel [m]
    int bumps = 0;                    // extended UMBmark bumps on the first leg
    double bump_loss = 0.0;           // travel loss of each of them [m]
    double first_leg = 4.0;           // length of the first leg [m]
    bool bumps_under_left = true;     // the inside wheel: left on ccw squares, right on cw
  };
  // UmbmarkFloor: seed selects the roughness sequence (runs are repeatable).
  UmbmarkFloor(const Options& o, std::uint64_t seed) noexcept;
  void perturb(double& d_left, double& d_right) noexcept override;

 private:
  double next_spacing() noexcept;

  Options o_;
  std::mt19937_64 rng_;
  std::uniform_real_distribution<double> unit_{0.0, 1.0};
  std::array<double, 2> to_next_{};  // distance to the next roughness bump per wheel [m]
  std::array<double, 2> pending_{};  // travel loss not yet applied per wheel [m]
  double leg_travel_ = 0.0;          // centre travel on the first leg so far [m]
  int bumps_done_ = 0;
  bool first_leg_ = true;
};

}  // namespace odo::sim
