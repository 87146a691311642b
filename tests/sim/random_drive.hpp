// random_drive: the simulated robot's ramped random driving, shared by the sim tier's
// false-alarm tests (the gyro's disagreement, the wheels' within-side slip).
#pragma once

#include <algorithm>
#include <cstdint>
#include <random>

#include "odo/sim/robot.hpp"

namespace odo::sim {

// DriveMix: what random_drive draws: a stop with probability `stop`, a turn on the spot with
// probability `spot` (up to 1 rad/s), otherwise an arc of v_min .. v_min + v_span [m/s] and up
// to w_max [rad/s]; each held hold_min .. hold_min + hold_span [s], after `still` s at rest.
struct DriveMix {
  double stop = 0.2, spot = 0.2;
  double v_min = 0.05, v_span = 0.45, w_max = 0.5;
  double hold_min = 1.0, hold_span = 9.0;
  double still = 2.0;
};

// Ramped random driving (the default mix: stops, on-the-spot turns and arcs of 0.05-0.5 m/s, up
// to 0.5 rad/s, each held 1-10 s), wheel speeds ramped at 1 m/s^2 in 10 ms steps (a real base
// accelerates; a velocity step would be an infinite acceleration and rightly flagged).
inline Scenario random_drive(double seconds, std::uint64_t seed, const RobotGeometry& g,
                             const DriveMix& m = {}) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const double r = g.wheel_diameter_left / 2.0, b = g.wheelbase;
  Scenario sc{{m.still, 0.0, 0.0}};
  double vl = 0.0, vr = 0.0, t = m.still;
  while (t < seconds) {
    double tl = 0.0, tr = 0.0;
    const double pick = u(rng);
    if (pick < m.stop) {                  // stop
    } else if (pick < m.stop + m.spot) {  // on the spot
      tr = (2.0 * u(rng) - 1.0) * b / 2.0;
      tl = -tr;
    } else {
      const double v = m.v_min + m.v_span * u(rng), w = (2.0 * u(rng) - 1.0) * m.w_max;
      tl = v - w * b / 2.0;
      tr = v + w * b / 2.0;
    }
    while (vl != tl || vr != tr) {
      vl += std::clamp(tl - vl, -0.01, 0.01);
      vr += std::clamp(tr - vr, -0.01, 0.01);
      sc.push_back({0.01, vl / r, vr / r});
      t += 0.01;
    }
    const double hold = m.hold_min + m.hold_span * u(rng);
    sc.push_back({hold, vl / r, vr / r});
    t += hold;
  }
  return sc;
}

}  // namespace odo::sim
