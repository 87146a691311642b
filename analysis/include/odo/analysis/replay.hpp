// Replay: integrate a log of raw counter readings offline with the same odometry as the loop.
#pragma once

#include <cstdint>
#include <istream>
#include <string>

#include "odo/hal/result.hpp"
#include "odo/odometry/kinematics.hpp"
#include "odo/odometry/pose.hpp"

namespace odo::analysis {

struct ReplayResult {
  Pose2 pose;                 // final pose, theta cumulative
  double distance = 0.0;      // path length of the centre point [m]
  std::uint64_t samples = 0;  // data rows read
};

// replay_ticks: reads CSV `t,left,right` (t [s] non-decreasing, raw `bits`-wide readings,
// signed or unsigned) from `in` and integrates it; errors name `source`, the line and the field.
Result<ReplayResult> replay_ticks(std::istream& in, const std::string& source, const Kinematics& k,
                                  int bits);

}  // namespace odo::analysis
