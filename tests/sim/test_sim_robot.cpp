#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "odo/sim/robot.hpp"

namespace odo::sim {
namespace {

TEST(SimRobot, StraightRunAndQuantisedCounts) {
  // Both wheels 2 rad/s for 1 s, D = 0.15 m: each wheel rolls 2 * 0.075 = 0.15 m.
  // Counts: 2 rad * (2048 * 16) / (2 pi) = 10430.378 counts, + 0.5 phase -> floor = 10430.
  RobotGeometry g;
  auto r = SimRobot::create(g, {{1.0, 2.0, 2.0}});
  ASSERT_TRUE(r.ok());
  r->advance_to(kNsPerSecond);
  EXPECT_NEAR(r->true_pose().x, 0.15, 1e-12);
  EXPECT_NEAR(r->true_pose().y, 0.0, 1e-15);
  EXPECT_EQ(r->counts_left(), 10430);
  EXPECT_EQ(r->counts_right(), 10430);
}

TEST(SimRobot, CountsChangeOnlyOnWholeStates) {
  // One count is 2 pi / 32768 rad of wheel; from phase 0.5 the first count arrives after half
  // of it, the second after one and a half.
  RobotGeometry g;
  const double count_rad = 2 * std::numbers::pi / 32768.0;
  auto r = SimRobot::create(g, {{1.0, count_rad, -count_rad}});  // one count per second
  r->advance_to(from_seconds(0.49));
  EXPECT_EQ(r->counts_left(), 0);
  EXPECT_EQ(r->counts_right(), 0);
  r->advance_to(from_seconds(0.51));
  EXPECT_EQ(r->counts_left(), 1);
  EXPECT_EQ(r->counts_right(), -1);  // backwards: crosses -0.5 -> state -1
  r->advance_to(from_seconds(0.99));
  EXPECT_EQ(r->counts_left(), 1);
}

TEST(SimRobot, StandsStillAfterScenario) {
  RobotGeometry g;
  auto r = SimRobot::create(g, {{1.0, 1.0, 1.0}});
  r->advance_to(from_seconds(5.0));
  EXPECT_TRUE(r->finished());
  EXPECT_NEAR(r->true_pose().x, 0.075, 1e-12);
}

TEST(SimRobot, LabmateGeometry) {
  // D_R / D_L = 0.9985 and (D_L + D_R)/2 = Dn.
  const RobotGeometry g = labmate_geometry(0.15);
  EXPECT_NEAR(g.wheel_diameter_right / g.wheel_diameter_left, 0.9985, 1e-15);
  EXPECT_NEAR((g.wheel_diameter_left + g.wheel_diameter_right) / 2, 0.15, 1e-15);
  EXPECT_DOUBLE_EQ(g.wheelbase, 0.337);
}

TEST(SimRobot, RejectsBadGeometry) {
  RobotGeometry g;
  g.wheelbase = -1;
  auto r = SimRobot::create(g, {});
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().message.find("wheelbase"), std::string::npos);
}

}  // namespace
}  // namespace odo::sim
