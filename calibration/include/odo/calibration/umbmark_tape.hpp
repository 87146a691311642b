// The return error of one UMBmark run from what a person measures on a real robot: the
// odometry's pose at start and end (daemon frame) and tape distances of the robot's reference
// point to two walls (or floor lines) of an L-shaped corner at the start mark.
#pragma once

#include <optional>

#include "odo/calibration/umbmark.hpp"
#include "odo/hal/choice.hpp"
#include "odo/odometry/pose.hpp"

namespace odo::calib {

// SideWall: which side of the start pose the side wall is on (the back wall is behind it).
enum class SideWall { kLeft, kRight };

// kSideWalls: how a person writes a SideWall (odomctl umbmark record --side-wall).
inline constexpr Choice<SideWall> kSideWalls[] = {{SideWall::kLeft, "left"},
                                                  {SideWall::kRight, "right"}};

// TapeReading: distances [m] of the reference point to the back wall (along x of the start
// frame) and to the side wall (along y), taken with the robot standing still.
struct TapeReading {
  double back = 0.0;  // [m]
  double side = 0.0;  // [m]
};

// tape_return_error: Eq. 3.1 in the start frame (x along the first leg, y left): the absolute
// displacement from the tape (back: end - start; left wall: start - end; right wall: end -
// start) minus the odometry's displacement odo_start^-1 * odo_end. etheta [rad] is the measured
// heading change (CCW +) minus the odometry's, wrapped to (-pi, pi]; nullopt when not measured.
UmbmarkRun tape_return_error(Direction dir, bool bumps, SideWall wall, const TapeReading& start,
                             const TapeReading& end, std::optional<double> heading_change,
                             const Pose2& odo_start, const Pose2& odo_end);

}  // namespace odo::calib
