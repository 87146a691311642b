// calib::tape_return_error: Eq. 3.1 from tape distances and the odometry's start and end poses.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "odo/calibration/umbmark_tape.hpp"

namespace odo::calib {
namespace {

constexpr double kPi = std::numbers::pi;

TEST(UmbmarkTape, OdometryAtTheOriginLeftWall) {
  // Back wall 0.500 -> 0.530 m: the robot really ended 30 mm ahead (abs x = +0.030).
  // Left wall 0.400 -> 0.380 m: 20 mm closer to the left wall (abs y = +0.020).
  // Odometry believes (0.010, -0.005): ex = 0.030 - 0.010 = 0.020, ey = 0.020 + 0.005 = 0.025.
  const UmbmarkRun r =
      tape_return_error(Direction::kCw, false, SideWall::kLeft, {0.5, 0.4}, {0.53, 0.38},
                        std::nullopt, Pose2{0, 0, 0}, Pose2{0.010, -0.005, -2 * kPi + 0.001});
  EXPECT_EQ(r.direction, Direction::kCw);
  EXPECT_FALSE(r.bumps);
  EXPECT_NEAR(r.ex, 0.020, 1e-12);
  EXPECT_NEAR(r.ey, 0.025, 1e-12);
  EXPECT_FALSE(r.etheta.has_value());
}

TEST(UmbmarkTape, RightWallSignIsMirrored) {
  // Right wall 0.400 -> 0.380 m: 20 mm closer to a wall on the right is abs y = -0.020;
  // odometry (0, 0): ey = -0.020; back unchanged: ex = 0.
  const UmbmarkRun r = tape_return_error(Direction::kCcw, true, SideWall::kRight, {0.5, 0.4},
                                         {0.5, 0.38}, 0.0, Pose2{}, Pose2{});
  EXPECT_EQ(r.direction, Direction::kCcw);
  EXPECT_TRUE(r.bumps);
  EXPECT_NEAR(r.ex, 0.0, 1e-12);
  EXPECT_NEAR(r.ey, -0.020, 1e-12);
  ASSERT_TRUE(r.etheta.has_value());
  EXPECT_NEAR(*r.etheta, 0.0, 1e-12);
}

TEST(UmbmarkTape, OdometryDisplacementIsTakenInItsStartPose) {
  // The daemon's pose at the start is (1, 2, +90 deg): its x axis points along the daemon's +y.
  // It ends at (1.003, 2.010, 90 deg + 2 pi - 0.002 rad) (wrapped on the bus: 90 deg - 0.002).
  // Displacement in the start pose: x' = cos(90)*0.003 + sin(90)*0.010 = 0.010,
  // y' = -sin(90)*0.003 + cos(90)*0.010 = -0.003; heading change -0.002 rad.
  // Tape: abs x = 0.012, abs y (left wall 0.300 -> 0.301) = -0.001; heading measured +0.001.
  // ex = 0.012 - 0.010 = 0.002, ey = -0.001 + 0.003 = 0.002, etheta = 0.001 + 0.002 = 0.003.
  const double h = kPi / 2;
  const UmbmarkRun r =
      tape_return_error(Direction::kCw, false, SideWall::kLeft, {0.2, 0.3}, {0.212, 0.301}, 0.001,
                        Pose2{1.0, 2.0, h}, Pose2{1.003, 2.010, h - 0.002});
  EXPECT_NEAR(r.ex, 0.002, 1e-12);
  EXPECT_NEAR(r.ey, 0.002, 1e-12);
  ASSERT_TRUE(r.etheta.has_value());
  EXPECT_NEAR(*r.etheta, 0.003, 1e-12);
}

TEST(UmbmarkTape, HeadingErrorIsWrapped) {
  // Odometry turned -2 pi + 0.001 (a cw square, cumulative), the person measured -0.002 rad
  // (wrapped): etheta = -0.002 - (-2 pi + 0.001) = 2 pi - 0.003 -> wrapped -0.003.
  const UmbmarkRun r =
      tape_return_error(Direction::kCw, false, SideWall::kLeft, {0.5, 0.4}, {0.5, 0.4}, -0.002,
                        Pose2{}, Pose2{0.0, 0.0, -2 * kPi + 0.001});
  ASSERT_TRUE(r.etheta.has_value());
  EXPECT_NEAR(*r.etheta, -0.003, 1e-12);
}

}  // namespace
}  // namespace odo::calib
