// Replay: integrate a log of raw counter readings offline with the same odometry as the loop.
#pragma once

#include <cstdint>
#include <istream>
#include <string>

#include "odo/hal/result.hpp"
#include "odo/odometry/gyrodometry.hpp"
#include "odo/odometry/kinematics.hpp"
#include "odo/odometry/pose.hpp"

namespace odo::analysis {

struct ReplayResult {
  Pose2 pose;                 // final pose, theta cumulative
  double distance = 0.0;      // path length of the centre point [m]
  std::uint64_t samples = 0;  // data rows read
  bool fused = false;         // the gyro_z column was fused (gyrodometry)
  FusionCounters fusion;      // when fused: events detected, gyro-heading ticks
};

// ReplayGyro: how replay_ticks treats an optional `gyro_z` column [rad/s, the mean rate over
// the interval that ends at that row's t].
struct ReplayGyro {
  bool use = true;  // false (--no-gyro): the column is read and checked, but not fused
  // The loop's fusion parameters; tick is set from the log's first interval and
  // heading_quantum from the kinematics, as the loop sets them from its rate.
  GyrodometryParams params;
};

// replay_ticks: reads CSV `t,left,right` (t [s] non-decreasing, raw `bits`-wide readings,
// signed or unsigned) from `in` and integrates it; errors name `source`, the line and the field.
Result<ReplayResult> replay_ticks(std::istream& in, const std::string& source, const Kinematics& k,
                                  int bits);
// replay_ticks: the same with an optional fourth column gyro_z fused by the loop's rule
// (Gyrodometry::step, Odometry::update_fused) when `gyro` is given and gyro->use.
Result<ReplayResult> replay_ticks(std::istream& in, const std::string& source, const Kinematics& k,
                                  int bits, const ReplayGyro& gyro);

}  // namespace odo::analysis
