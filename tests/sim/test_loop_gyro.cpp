// The gyrodometry fusion inside the firmware's loop (issue 16): the simulated robot, its
// encoders and a simulated consumer gyro through sim::SimRun, the loop fusing every tick.
#include <gtest/gtest.h>

#include <cmath>

#include "odo/loop/state_record.hpp"
#include "odo/odometry/error_model.hpp"
#include "odo/sim/floor.hpp"
#include "odo/sim/sim_run.hpp"

namespace odo::sim {
namespace {

// Straight 20 s at 0.2 m/s on a robot that is exactly what odometry believes, at 200 Hz.
struct Leg {
  RobotGeometry geo;  // 0.15 m wheels, 2048 x 16 counts, b = 0.34 m
  Kinematics k = Kinematics::create(nominal_params(0.15, geo.wheelbase, geo)).value();
  GyroModel model = consumer_gyro();
  Scenario scenario() const {
    const double w = 0.2 / 0.075;
    return Scenario{{20.0, w, w}, {1.0, 0.0, 0.0}};
  }
  std::unique_ptr<SimRun> run(TravelPerturbation* floor, bool gyro) {
    SimRunOptions o;
    o.loop.rate_hz = 200.0;
    o.perturbation = floor;
    o.gyro = gyro ? &model : nullptr;
    o.gyro_seed = 3;
    // Both runs stand still first, so the gyro's lead-in does not shift the floor's bumps.
    Scenario s = scenario();
    if (!gyro) s.insert(s.begin(), Segment{o.gyro_lead_in, 0.0, 0.0});
    return SimRun::create(geo, k, s, o).value();
  }
};

UmbmarkFloor::Options bumps(int n) {
  UmbmarkFloor::Options fo;
  fo.bumps = n;
  fo.bump_loss = bump_travel_loss(0.075, 0.010);  // 10 mm bumps: 3.514 mm of travel each
  return fo;
}

TEST(LoopGyro, BumpsOnALegAreRejectedInTheLoop) {
  // Ten 10 mm bumps under the left wheel turn odometry's heading by 10 * 3.514e-3 / 0.34 =
  // 0.1034 rad (sim_gyro's SimGyrodometry test derives it); the loop with the gyro fused must be
  // 10x better and count the ten bumps.
  Leg leg;
  UmbmarkFloor f1(bumps(10), 1), f2(bumps(10), 1);
  auto plain = leg.run(&f1, false);
  auto fused = leg.run(&f2, true);
  plain->drive(0.0);
  fused->drive(0.0);
  const double e_plain = std::fabs(plain->error().theta);
  const double e_fused = std::fabs(fused->error().theta);
  EXPECT_NEAR(e_plain, 0.1034, 1e-3);
  EXPECT_LT(e_fused, e_plain / 10.0);
  const Gyrodometry* g = fused->loop().fusion();
  ASSERT_NE(g, nullptr);
  EXPECT_GE(g->counters().disagreements, 10u);
  EXPECT_LE(g->counters().disagreements, 12u);
  const loop::LoopGyroStatus& st = fused->loop().snapshot().gyro;
  EXPECT_TRUE(st.enabled);
  EXPECT_TRUE(st.bias_valid);
  EXPECT_EQ(st.fusion.disagreements, g->counters().disagreements);
  EXPECT_GT(st.fusion.gyro_used_ticks, 0u);
  // The heading's variance grew over the flagged intervals from the gyro's noise: positive and
  // finite (not the wheels' alone: set-pose below makes it zero again).
  EXPECT_GT(fused->loop().odometry().covariance()[8], 0.0);
  std::printf("loop, 10 bumps: odometry %.3e rad, fused %.3e rad, %llu events\n", e_plain, e_fused,
              static_cast<unsigned long long>(g->counters().disagreements));
}

TEST(LoopGyro, SmoothLegIsOdometryBitForBit) {
  // No bumps, no limits reached on a straight leg after the lead-in: nothing is flagged and the
  // loop's pose is exactly odometry's.
  Leg leg;
  auto plain = leg.run(nullptr, false);
  auto fused = leg.run(nullptr, true);
  plain->drive(0.0);
  fused->drive(0.0);
  EXPECT_EQ(fused->loop().fusion()->counters().gyro_used_ticks, 0u);
  EXPECT_EQ(fused->loop().odometry().pose().x, plain->loop().odometry().pose().x);
  EXPECT_EQ(fused->loop().odometry().pose().y, plain->loop().odometry().pose().y);
  EXPECT_EQ(fused->loop().odometry().pose().theta, plain->loop().odometry().pose().theta);
  EXPECT_EQ(fused->loop().odometry().covariance(), plain->loop().odometry().covariance());
}

TEST(LoopGyro, FaultyGyroFallsBackToOdometry) {
  // Fault-matrix rows: the gyro goes silent (stale), saturates, returns NaN, each during a bump
  // run on smooth floor; the fusion flags the fault and the pose stays odometry's exactly.
  for (int fault = 0; fault < 3; ++fault) {
    Leg leg;
    auto plain = leg.run(nullptr, false);
    auto fused = leg.run(nullptr, true);
    plain->drive(0.0);
    SimGyro* g = fused->gyro();
    ASSERT_NE(g, nullptr);
    loop::OdometryLoop& lp = fused->loop();
    lp.start();
    for (int i = 0; i < 4200; ++i) {  // 21 s at 200 Hz
      if (i == 1000) {
        if (fault == 0) g->arm_silence(500'000'000);
        if (fault == 1) g->arm_saturation(50);
        if (fault == 2) g->arm_nan(20);
      }
      lp.tick();
    }
    const Gyrodometry* f = lp.fusion();
    EXPECT_GE(f->counters().gyro_faults, 1u) << fault;
    EXPECT_EQ(lp.snapshot().gyro.fusion.gyro_faults, f->counters().gyro_faults) << fault;
    EXPECT_TRUE(std::isfinite(lp.odometry().pose().theta)) << fault;
    EXPECT_NEAR(lp.odometry().pose().theta, plain->loop().odometry().pose().theta, 1e-12) << fault;
    EXPECT_NEAR(lp.odometry().pose().x, plain->loop().odometry().pose().x, 1e-9) << fault;
  }
}

TEST(LoopGyro, SetPoseMidLegKeepsTheFusionRight) {
  // A set-pose (to zero) halfway along the bump leg: the fusion's window is reset with the pose,
  // and the heading from there on is the true turn since the reset to within a tenth of what
  // the bumps after it do to odometry alone (about half of 0.1034 rad).
  Leg leg;
  UmbmarkFloor f(bumps(10), 1);
  auto fused = leg.run(&f, true);
  loop::OdometryLoop& lp = fused->loop();
  lp.start();
  double truth_at_reset = 0.0;
  for (int i = 0; i < 4400; ++i) {
    if (i == 2200) {
      ASSERT_TRUE(lp.post(loop::SetPose{Pose2{}}));
      truth_at_reset = fused->robot().true_pose().theta;
    }
    lp.tick();
  }
  EXPECT_EQ(lp.commands_applied(), 1u);
  const double turned = fused->robot().true_pose().theta - truth_at_reset;
  EXPECT_LT(std::fabs(lp.odometry().pose().theta - turned), 0.1034 / 2.0 / 10.0);
}

// restart_mid_leg: the bump leg with the process restarted 2 s into the drive (0.1 s down, the
// robot rolling on): the state record goes through its bytes to a new loop on the same robot,
// encoders and gyro; its gyro id matches the record's or not; the counts count on while the
// loop is down (continuous) or not (GPIO quadrature: the pose starts fresh). The heading error
// at the end: against the true heading, or with a fresh pose against the true turn since then.
struct Restarted {
  loop::ResumeDecision decision;
  double heading_error = 0.0;
  std::uint64_t events = 0;
};
Restarted restart_mid_leg(bool same_gyro, bool continuous = true) {
  Leg leg;
  UmbmarkFloor f(bumps(10), 1);
  auto run = leg.run(&f, true);
  loop::OdometryLoop& first = run->loop();
  first.start();
  for (int i = 0; i < 600; ++i) first.tick();  // 1 s lead-in and 2 s of the leg at 200 Hz
  loop::StateRecord rec;
  loop::fill_state_record(first, rec);
  rec.sequence = 1;
  rec.gyro_id = 7;
  loop::StateBytes bytes{};
  loop::encode_state(rec, bytes);
  run->clock().advance(from_seconds(0.1));
  auto second = loop::OdometryLoop::create(run->loop_config(), leg.k, run->encoder(), run->clock(),
                                           run->gyro())
                    .value();
  loop::ResumeContext c;
  c.max_age = from_seconds(1.0);
  c.backend_continuous = continuous;  // the simulated robot's counters do; GPIO's would not
  c.counter_bits = second->counter_bits();
  c.metres_per_count_left = leg.k.metres_per_count_left();
  c.metres_per_count_right = leg.k.metres_per_count_right();
  c.wheelbase = leg.k.wheelbase();
  c.gyro_id = same_gyro ? 7 : 8;
  second->resume_from(loop::decode_state(bytes).value(), c);
  second->start();
  const double start_theta = continuous ? 0.0 : run->robot().true_pose().theta;
  while (second->last_stamp() < from_seconds(22.0)) second->tick();
  return {second->resume_decision(),
          run->robot().true_pose().theta - start_theta - second->odometry().pose().theta,
          second->fusion()->counters().disagreements};
}

TEST(LoopGyro, RestartMidLegKeepsDetectingWithTheRestoredBias) {
  // 2 s of the 20 s leg are done at the restart: the bumps after it turn odometry's heading by
  // most of the leg's 0.1034 rad. With the gyro's bias restored (same gyro) the fusion rejects
  // them as if there had been no restart (LoopGyro.BumpsOnALegAreRejectedInTheLoop's 10x); with
  // another gyro's record it has no bias until the standstill at the end, and keeps them.
  const Restarted same = restart_mid_leg(true);
  const Restarted other = restart_mid_leg(false);
  ASSERT_TRUE(same.decision.resumed()) << loop::resume_reason_name(same.decision.reason);
  ASSERT_TRUE(other.decision.resumed());
  EXPECT_TRUE(same.decision.gyro_restored);
  EXPECT_FALSE(other.decision.gyro_restored);
  EXPECT_GT(same.decision.gyro.bias_time, 0.0);
  EXPECT_LT(std::fabs(same.heading_error), 0.1034 / 10.0);
  EXPECT_GT(std::fabs(other.heading_error), 0.1034 / 2.0);
  EXPECT_GE(same.events, 8u);
  EXPECT_EQ(other.events, 0u);
  std::printf("restart 2 s into the bump leg: heading error %.3e rad restored, %.3e rad not\n",
              same.heading_error, other.heading_error);
}

TEST(LoopGyro, FreshPoseAfterARestartStillGetsTheBias) {
  // Counts lost while the loop was down (GPIO quadrature): the pose starts fresh
  // (not-continuous), but the gyro is the same chip in the same boot: its bias is restored
  // (its scale is not: learnt against the old pose's odometry), and the bumps after the restart
  // are rejected as in the test above: heading since the restart within a tenth of theirs.
  const Restarted fresh = restart_mid_leg(true, false);
  EXPECT_EQ(fresh.decision.reason, loop::ResumeReason::kNotContinuous);
  EXPECT_TRUE(fresh.decision.gyro_restored);
  EXPECT_FALSE(fresh.decision.gyro.scale_valid);
  EXPECT_LT(std::fabs(fresh.heading_error), 0.1034 / 10.0);
  EXPECT_GE(fresh.events, 8u);
  std::printf("fresh pose after the restart, bias restored: heading error %.3e rad\n",
              fresh.heading_error);
}

// The tick's motion in the snapshot (issue 33): consumers (the ROS 2 twist covariance, the
// twist Monte Carlo) take each tick's wheel travels, interval and wheelbase from it instead of
// inverting (v, w) with a wheelbase captured at start.
void expect_wheel_twist(const loop::LoopSnapshot& s, double b) {
  const TickMotion& m = s.motion;
  ASSERT_GT(m.dt, 0.0);
  EXPECT_FALSE(m.gyro_heading);
  EXPECT_EQ(m.wheelbase, b);
  // Chong-Kleeman per wheel, k^2 |d|; v and omega are the travels' difference quotients.
  const ErrorModelParams k;
  const double wl = k.k_left * k.k_left * std::fabs(m.d_left);
  const double wr = k.k_right * k.k_right * std::fabs(m.d_right);
  const double dt2 = m.dt * m.dt;
  const Cov2 c = twist_covariance(m, k);
  EXPECT_DOUBLE_EQ(c[0], (wl + wr) / (4.0 * dt2));
  EXPECT_DOUBLE_EQ(c[3], (wl + wr) / (b * b * dt2));
  EXPECT_DOUBLE_EQ(c[1], (wr - wl) / (2.0 * b * dt2));
  EXPECT_DOUBLE_EQ(s.v, 0.5 * (m.d_left + m.d_right) / m.dt);
}

TEST(LoopMotion, SetKinematicsChangesTheTwistCovarianceAtOnce) {
  // A calibration result (or a SIGHUP reload) arrives mid-run with b = 0.36 m instead of 0.34 m:
  // from the next tick on the snapshot says so, and the twist covariance follows the new b
  // (omega's variance by (0.34 / 0.36)^2 for the same travels).
  Leg leg;
  auto run = leg.run(nullptr, false);
  loop::OdometryLoop& loop = run->loop();
  for (int t = 0; t < 400; ++t) loop.tick();  // 2 s: standing 1 s, then the leg
  expect_wheel_twist(loop.snapshot(), 0.34);
  EXPECT_GT(std::fabs(loop.snapshot().motion.d_left), 0.0);
  KinematicParams p = leg.k.params();
  p.wheelbase = 0.36;
  ASSERT_TRUE(loop.post(loop::SetKinematics{*Kinematics::create(p), calib::StoreStatus::kOk}));
  loop.tick();
  expect_wheel_twist(loop.snapshot(), 0.36);
  EXPECT_EQ(loop.snapshot().motion.d_left, loop.odometry().last_d_left());
  EXPECT_EQ(loop.snapshot().motion.d_right, loop.odometry().last_d_right());
}

TEST(LoopMotion, GyroFusedTickTakesOmegasVarianceFromTheGyro) {
  // Ten bumps under the left wheel: the fusion replaces odometry's heading on some ticks. On
  // each, omega is the gyro's: its variance is the fused increment's over dt^2 and independent
  // of the wheels (no cross term); on the others it is the wheels'.
  Leg leg;
  UmbmarkFloor floor(bumps(10), 1);
  auto run = leg.run(&floor, true);
  loop::OdometryLoop& loop = run->loop();
  int fused = 0;
  for (int t = 0; t < 200 * 22; ++t) {
    loop.tick();
    const loop::LoopSnapshot& s = loop.snapshot();
    const bool gyro = (s.gyro.fusion_flags & kFusionGyroUsed) != 0;
    ASSERT_EQ(s.motion.gyro_heading, gyro) << "tick " << t;
    if (!gyro) continue;
    ++fused;
    const Cov2 c = twist_covariance(s.motion, ErrorModelParams{});
    EXPECT_GT(s.motion.gyro_var_heading, 0.0);
    EXPECT_DOUBLE_EQ(c[3], s.motion.gyro_var_heading / (s.motion.dt * s.motion.dt));
    EXPECT_EQ(c[1], 0.0);
  }
  EXPECT_GT(fused, 10);
}

}  // namespace
}  // namespace odo::sim
