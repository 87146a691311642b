// The loop's pose covariance: filled every tick, equal to the closed form of the driven path,
// reset by a set-pose command, and validated by the configured k_L, k_R.
#include <gtest/gtest.h>

#include <cmath>

#include "odo/odometry/error_model.hpp"
#include "sim_fixture.hpp"

namespace odo::test {
namespace {

TEST(LoopCovariance, StraightRunMatchesClosedForm) {
  // 10 m straight at 0.5 m/s on the nominal robot (true geometry = believed). Each tick's counts
  // differ by at most one between the wheels, so the path is a straight line up to heading
  // wiggles of 1 count / b = 1.4e-5 m / 0.34 m; the loop's tick-by-tick covariance must match the
  // one-segment straight-line closed form of the total travel (consistency) to 1e-4.
  const KinematicParams p = nominal_labmate();
  const auto k = *Kinematics::create(p);
  sim::RobotGeometry g;  // 0.15 m wheels, 0.34 m wheelbase: the nominal robot
  const double omega = 0.5 / 0.075;
  SimRun run(g, k, {{20.0, omega, omega}});
  run.drive(0.5);
  const loop::LoopSnapshot& s = run.loop->snapshot();
  ASSERT_TRUE(s.has_cov);
  const double d = s.distance;
  EXPECT_NEAR(d, 10.0, 1e-3);
  Cov3 expect{};
  propagate_arc(expect, 0.0, d, d, 0.34, ErrorModelParams{});
  for (int i = 0; i < 9; ++i) {
    const double scale = std::sqrt(expect[4 * (i / 3)] * expect[4 * (i % 3)]);
    EXPECT_NEAR(s.cov[i], expect[i], 1e-4 * scale) << "entry " << i;
  }
  EXPECT_EQ(s.cov[1], s.cov[3]);
}

TEST(LoopCovariance, SetPoseResetsCovarianceToZero) {
  const auto k = *Kinematics::create(nominal_labmate());
  SimRun run(sim::RobotGeometry{}, k, {{60.0, 3.0, 3.3}});
  std::atomic<bool> stop{false};
  run.loop->run(from_seconds(2.0), stop);
  const double before = run.loop->snapshot().cov[8];
  EXPECT_GT(before, 0.0);
  run.loop->post(loop::SetPose{{1.0, 2.0, 0.5}});
  run.loop->tick();
  // One tick of motion after the reset: the covariance is that of the tick alone.
  const loop::LoopSnapshot& s = run.loop->snapshot();
  Cov3 one{};
  propagate_arc(one, 0.5, run.loop->odometry().last_d_left(), run.loop->odometry().last_d_right(),
                0.34, ErrorModelParams{});
  for (int i = 0; i < 9; ++i) EXPECT_DOUBLE_EQ(s.cov[i], one[i]) << "entry " << i;
  EXPECT_LT(s.cov[8], before / 100);
}

TEST(LoopCovariance, RejectsBadCoefficients) {
  sim::VirtualClock clock;
  auto robot = *sim::SimRobot::create(sim::RobotGeometry{}, {});
  sim::SimEncoderSource enc(robot);
  loop::LoopConfig cfg;
  cfg.error_model.k_right = -1.0;
  auto r = loop::OdometryLoop::create(cfg, *Kinematics::create(nominal_labmate()), enc, clock);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().message.find("error_model.k_right = -1"), std::string::npos)
      << r.error().message;
}

}  // namespace
}  // namespace odo::test
