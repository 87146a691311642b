#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "odo/sim/floor.hpp"
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

// Reference truth: one exact arc_step with a fresh sin and cos per step, stepped like advance_to.
struct ArcStepRobot {
  RobotGeometry g;
  Scenario sc;
  TravelPerturbation* perturbation = nullptr;
  std::size_t seg = 0;
  TimeNs seg_start = 0, t = 0;
  Pose2 pose;
  void advance_to(TimeNs to) {
    while (t < to && seg < sc.size()) {
      const TimeNs end = seg_start + from_seconds(sc[seg].duration);
      const TimeNs until = to < end ? to : end;
      const double dt = to_seconds(until - t);
      double d_l = sc[seg].omega_left * dt * g.wheel_diameter_left / 2.0;
      double d_r = sc[seg].omega_right * dt * g.wheel_diameter_right / 2.0;
      if (perturbation != nullptr) perturbation->perturb(d_l, d_r);
      pose = arc_step(pose, d_l, d_r, g.wheelbase);
      t = until;
      if (t >= end) {
        ++seg;
        seg_start = end;
      }
    }
  }
};

double max_deviation(SimRobot& r, ArcStepRobot& ref, TimeNs step, TimeNs until) {
  double worst = 0.0;
  for (TimeNs t = step; t <= until; t += step) {
    r.advance_to(t);
    ref.advance_to(t);
    EXPECT_EQ(r.true_pose().theta, ref.pose.theta);  // the heading is summed the same way
    worst =
        std::fmax(worst, std::hypot(r.true_pose().x - ref.pose.x, r.true_pose().y - ref.pose.y));
  }
  return worst;
}

TEST(SimRobot, CarriedHeadingMatchesSinCosPerStepOverLongRuns) {
  // The robot rotates a carried sin/cos instead of calling them every step; over 10^6 steps of
  // 1 ms on an arc (about 236 m) its truth stays within 1e-12 m of a sin and cos per step.
  RobotGeometry g;
  const Scenario arc{{1e4, 3.0, 3.3}};
  auto r = SimRobot::create(g, arc);
  ArcStepRobot ref{g, arc};
  EXPECT_LT(max_deviation(*r, ref, 1'000'000, from_seconds(1000.0)), 1e-12);
}

TEST(SimRobot, CarriedHeadingMatchesSinCosPerStepOnBumpyUmbmarkSquare) {
  // Segment boundaries, on-the-spot turns, pauses and a perturbation hook that changes every
  // step's travels (floor roughness and the ten bumps): same truth to 1e-13 m at 1 kHz.
  const RobotGeometry g = labmate_geometry(0.15);
  const auto k = *Kinematics::create({0.15, 2048, 16, 0.34, 0.34, 1.0, 1.0});
  const Scenario sq = square_scenario(k, SquareOptions{});
  UmbmarkFloor::Options fo;
  fo.roughness_height = 0.001;
  fo.bumps = 10;
  fo.bump_loss = 0.002;
  UmbmarkFloor floor_a(fo, 7), floor_b(fo, 7);
  auto r = SimRobot::create(g, sq);
  r->set_travel_perturbation(&floor_a);
  ArcStepRobot ref{g, sq, &floor_b};
  EXPECT_LT(max_deviation(*r, ref, 1'000'000, from_seconds(scenario_duration(sq) + 1.0)), 1e-13);
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
