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

TEST(LoopCovariance, MergedTicksAt1kHzGiveTheSamePoseAndCovariance) {
  // error_model.covariance_ticks = 10 at 1 kHz (the microcontroller's setting): the pose is
  // untouched (the merge is the covariance's alone) and the final covariance, flushed when the
  // run ends, is the tick-by-tick one up to how the curvature changes inside the groups that
  // span a change of segment (error_model's unit tests bound that at 3e-6 of the scale on a
  // rounded square; this path has a pivot, where the groups close at the reversing wheel).
  const auto k = *Kinematics::create(nominal_labmate());
  const sim::Scenario sc = {{3.0, 6.0, 6.0}, {2.0, 5.0, 7.0}, {1.0, -4.0, 4.0}, {3.0, 6.0, 6.0}};
  Cov3 cov[2];
  Pose2 pose[2];
  for (int i = 0; i < 2; ++i) {
    sim::SimRunOptions o;
    o.loop.rate_hz = 1000.0;
    o.loop.error_model.covariance_ticks = i == 0 ? 1 : 10;
    auto run = sim::SimRun::create(sim::RobotGeometry{}, k, sc, o).value();
    run->drive(0.5);
    EXPECT_EQ(run->loop().odometry().covariance(), run->loop().snapshot().cov);
    cov[i] = run->loop().snapshot().cov;
    pose[i] = run->loop().snapshot().pose;
  }
  EXPECT_EQ(pose[1].x, pose[0].x);
  EXPECT_EQ(pose[1].y, pose[0].y);
  EXPECT_EQ(pose[1].theta, pose[0].theta);
  EXPECT_GT(cov[0][8], 0.0);
  for (int i = 0; i < 9; ++i) {
    const double scale = std::sqrt(cov[0][4 * (i / 3)] * cov[0][4 * (i % 3)]);
    EXPECT_NEAR(cov[1][i], cov[0][i], 3e-6 * scale) << "entry " << i;
  }
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
  cfg.error_model = {};
  cfg.error_model.covariance_ticks = 0;
  r = loop::OdometryLoop::create(cfg, *Kinematics::create(nominal_labmate()), enc, clock);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().message.find("error_model.covariance_ticks = 0"), std::string::npos)
      << r.error().message;
}

}  // namespace
}  // namespace odo::test
