#include "odo/calibration/umbmark_tape.hpp"

#include <cmath>

namespace odo::calib {

UmbmarkRun tape_return_error(Direction dir, bool bumps, SideWall wall, const TapeReading& start,
                             const TapeReading& end, std::optional<double> heading_change,
                             const Pose2& odo_start, const Pose2& odo_end) {
  // Moving forward (+x) takes the point away from the back wall; moving left (+y) takes it
  // towards a left wall and away from a right one.
  const double abs_x = end.back - start.back;
  const double abs_y = wall == SideWall::kLeft ? start.side - end.side : end.side - start.side;
  // The odometry's displacement expressed in its own start pose (the daemon's pose does not
  // restart at zero for every run).
  const double dx = odo_end.x - odo_start.x, dy = odo_end.y - odo_start.y;
  const double c = std::cos(odo_start.theta), s = std::sin(odo_start.theta);
  UmbmarkRun r;
  r.direction = dir;
  r.bumps = bumps;
  r.ex = abs_x - (c * dx + s * dy);
  r.ey = abs_y - (-s * dx + c * dy);
  if (heading_change) {
    r.etheta = wrap_angle(*heading_change - (odo_end.theta - odo_start.theta));
  }
  return r;
}

}  // namespace odo::calib
