// Several encoders per side on the simulated robot (issue 38): the wheel model, a counter fault
// dropped without a trace, a lifted or spinning wheel flagged, no flag on a smooth floor.
// The benchmark figures of BENCHMARKS.md come from SideWheelsSim.FlagsLiftedAndSpinningWheels
// and SideWheelsSim.NoSlipFlagOnASmoothFloor (they print them).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <random>

#include "odo/hal/side_wheels.hpp"
#include "odo/sim/robot.hpp"
#include "odo/sim/side_wheels_sim.hpp"
#include "odo/sim/sim_run.hpp"
#include "random_drive.hpp"

namespace odo::sim {
namespace {

constexpr TimeNs kReadNs = 10'000'000;  // 100 Hz, the loop's default rate

SimSideWheelsSource make_source(SimRobot& robot, std::uint64_t seed, int bits = 16) {
  SideWheelsSimParams p;
  p.seed = seed;
  auto model = SideWheelsSim::create(p, robot.geometry());
  EXPECT_TRUE(model.ok());
  SideWheelsConfig c;  // the defaults: 0.1 s window, 8 counts + 10 %
  c.read_period = 1e-9 * kReadNs;
  auto src = SimSideWheelsSource::create(robot, std::move(model).value(), c, bits);
  EXPECT_TRUE(src.ok()) << (src.ok() ? "" : src.error().message);
  return std::move(src).value();
}

TEST(SideWheelsSim, TwoWheelsFollowTheSideWithinTheirRadiusTolerance) {
  // 10 s straight at 2 rad/s of wheel: 20 rad = 20 * 32768 / (2 pi) = 104303.1 counts of the
  // side's nominal wheel. Each wheel turns r / r_i of that, r_i within +-0.3 %: the combined
  // count (their mean) is within 0.3 % of it, and the 16-bit counters wrapped on the way.
  SimRobot robot = SimRobot::create(RobotGeometry{}, Scenario{{10.0, 2.0, 2.0}}).value();
  SimSideWheelsSource src = make_source(robot, 3);
  EncoderSample s;
  for (TimeNs t = 0; t <= 10 * kNsPerSecond; t += kReadNs) s = src.read(t);
  const double nominal = 20.0 * 32768.0 / (2.0 * 3.141592653589793);
  EXPECT_NEAR(static_cast<double>(s.left), nominal, 0.003 * nominal);
  const double mean_ratio = 0.5 * (src.model().radius_ratio(0, 0) + src.model().radius_ratio(0, 1));
  // The per-wheel noise over 1.5 m is k_w sqrt(1.5) = 1.2e-4 m = 9 counts (1 sigma) per wheel.
  EXPECT_NEAR(static_cast<double>(s.left), nominal * mean_ratio, 40.0);
  EXPECT_EQ(s.flags, 0u);
  EXPECT_EQ(src.counter_bits(), 64);
}

TEST(SideWheelsSim, CounterFaultIsDroppedAndLeavesNoTrace) {
  // The same robot and seed twice, once with wheel 1 of the left side faulting for 0.5 s: its
  // garbage counts never reach the combined count, which then differs only by that wheel's
  // share of the faulted interval (the mean of one wheel instead of two: the radius difference
  // and the noise of 0.5 s, a few counts).
  auto run = [](bool fault) {
    SimRobot robot = SimRobot::create(RobotGeometry{}, Scenario{{5.0, 2.0, 2.0}}).value();
    SimSideWheelsSource src = make_source(robot, 5);
    if (fault) src.model().inject(0, 1, WheelFault::kCounter, 2 * kNsPerSecond, 2500'000'000);
    EncoderSample s;
    std::uint32_t seen = 0;
    for (TimeNs t = 0; t <= 5 * kNsPerSecond; t += kReadNs) {
      s = src.read(t);
      seen |= s.flags;
    }
    s.flags = seen;
    return s;
  };
  const EncoderSample clean = run(false), faulted = run(true);
  EXPECT_EQ(clean.flags, 0u);
  EXPECT_EQ(faulted.flags, static_cast<std::uint32_t>(kEncoderWheelDropped));
  EXPECT_EQ(faulted.counters.wheel_drops, 1u);
  EXPECT_EQ(faulted.counters.slip_events, 0u);
  EXPECT_NEAR(static_cast<double>(faulted.left), static_cast<double>(clean.left), 50.0);
  EXPECT_EQ(faulted.right, clean.right);
}

// Driving for the injections: arcs of 0.1-0.5 m/s, up to 0.3 rad/s, held 2-6 s, ramped as
// random_drive ramps them, never stopping.
constexpr DriveMix kDriving{0.0, 0.0, 0.1, 0.4, 0.3, 2.0, 4.0, 0.01};

TEST(SideWheelsSim, FlagsLiftedAndSpinningWheels) {
  // 200 injections (ODO_SLIP_INJECTIONS for more), one every 4 s while driving: a random wheel
  // of a random side, lifted (remaining load 0) or spinning on a slippery patch (remaining load
  // 0.1-0.3), for a duration uniform in 0.1-2 s. Flagged: that side's slip flag rises between
  // the fault's start and one window after its end.
  const char* env = std::getenv("ODO_SLIP_INJECTIONS");
  const int n = env != nullptr ? std::max(1, std::atoi(env)) : 200;
  const RobotGeometry geo;
  SimRobot robot = SimRobot::create(geo, random_drive(4.0 * n + 10.0, 21, geo, kDriving)).value();
  SimSideWheelsSource src = make_source(robot, 7);
  std::mt19937_64 rng(99);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  int flagged = 0, lifted = 0, lifted_flagged = 0;
  double min_ratio = 1e9;
  TimeNs t = 0;
  for (int k = 0; k < n; ++k) {
    const TimeNs start = from_seconds(4.0 * k + 2.0);
    const double duration = 0.1 + 1.9 * u(rng);
    const TimeNs end = start + from_seconds(duration);
    const int side = u(rng) < 0.5 ? 0 : 1, wheel = u(rng) < 0.5 ? 0 : 1;
    const bool lift = k % 2 == 0;
    const double rho = lift ? 0.0 : 0.1 + 0.2 * u(rng);
    src.model().inject(side, wheel, WheelFault::kUnloaded, start, end, rho);
    const std::uint32_t bit = side == 0 ? kEncoderSlipLeft : kEncoderSlipRight;
    bool hit = false;
    double best = 0.0;
    for (; t < end + from_seconds(0.1) + kReadNs; t += kReadNs) {
      const EncoderSample s = src.read(t);
      if (t < start) continue;
      hit = hit || (s.flags & bit) != 0;
      best = std::max(best, side == 0 ? src.last().ratio_left : src.last().ratio_right);
    }
    min_ratio = std::min(min_ratio, best);
    flagged += hit ? 1 : 0;
    lifted += lift ? 1 : 0;
    lifted_flagged += lift && hit ? 1 : 0;
  }
  const double rate = static_cast<double>(flagged) / n;
  std::printf(
      "slip injections: %d of %d flagged (%.1f %%; lifted %d of %d, spinning %d of %d); the "
      "smallest peak spread / threshold of an injection %.3f\n",
      flagged, n, 100.0 * rate, lifted_flagged, lifted, flagged - lifted_flagged, n - lifted,
      min_ratio);
  EXPECT_GE(rate, 0.95);
}

TEST(SideWheelsSim, NoSlipFlagOnASmoothFloor) {
  // One hour (ODO_SLIP_SOAK_HOURS for more: the soak tier runs 24) of ramped random driving,
  // stops and turns on the spot included, two wheels per side with their radius tolerance and
  // count noise: no slip flag. Printed: the largest window spread / threshold, so the margin.
  const char* env = std::getenv("ODO_SLIP_SOAK_HOURS");
  const double hours = env != nullptr ? std::max(0.01, std::atof(env)) : 1.0;
  const RobotGeometry geo;
  SimRobot robot = SimRobot::create(geo, random_drive(3600.0 * hours, 13, geo)).value();
  SimSideWheelsSource src = make_source(robot, 11);
  double worst = 0.0;
  std::uint32_t seen = 0;
  const TimeNs until = from_seconds(3600.0 * hours);
  for (TimeNs t = 0; t <= until; t += kReadNs) {
    seen |= src.read(t).flags;
    worst = std::max({worst, src.last().ratio_left, src.last().ratio_right});
  }
  std::printf(
      "smooth floor: %g h, %llu slip events; largest window spread / threshold %.3f (threshold "
      "margin %.1fx)\n",
      hours, static_cast<unsigned long long>(src.combiner().counters().slip_events), worst,
      1.0 / worst);
  EXPECT_EQ(src.combiner().counters().slip_events, 0u);
  EXPECT_EQ(seen & (kEncoderSlipLeft | kEncoderSlipRight), 0u);
}

// A straight leg in the loop at 100 Hz (20 s at 0.2 m/s on a robot exactly as believed, two
// wheels per side), with the left side's wheel 0 lifted for 1 s at t = 10 s (after the lead-in).
struct LiftedLeg {
  RobotGeometry geo;
  Kinematics k = Kinematics::create(nominal_params(0.15, geo.wheelbase, geo)).value();
  GyroModel model = consumer_gyro();
  SideWheelsSimParams wheels;
  std::unique_ptr<SimRun> run(bool gyro, bool lift, bool both_sides = false) {
    SimRunOptions o;
    o.loop.rate_hz = 100.0;
    o.gyro = gyro ? &model : nullptr;
    o.gyro_seed = 3;
    o.side_wheels = &wheels;
    const double w = 0.2 / 0.075;
    Scenario s{{20.0, w, w}, {1.0, 0.0, 0.0}};
    if (!gyro) s.insert(s.begin(), Segment{o.gyro_lead_in, 0.0, 0.0});
    auto r = SimRun::create(geo, k, s, o).value();
    const TimeNs at = from_seconds(o.gyro_lead_in + 10.0);
    SideWheelsSim& m = r->side_wheels()->model();
    if (lift) m.inject(0, 0, WheelFault::kUnloaded, at, at + kNsPerSecond);
    if (both_sides) m.inject(1, 0, WheelFault::kUnloaded, at, at + kNsPerSecond);
    return r;
  }
};

TEST(SideWheelsLoop, SlipGrowsTheCovarianceByTheSpread) {
  // The lifted wheel spins 1 / (1 - 0.25) = 4/3 of the ground speed after tau_m = 0.05 s: over
  // the second its excess is 0.2 m/s * (1/3) * (1 - 0.05 (1 - e^-20)) = 0.0633 m, the side's
  // mean over-counts by half of it, and the heading is off by 0.0317 / 0.34 = 0.093 rad. The
  // interval's spread S ~ 0.0633 m enters as the left travel's variance S^2: heading variance
  // S^2 / b^2 = 0.0347 rad^2 (sigma 0.19 rad), so the error is within 1 sigma, where the wheels'
  // noise alone (k^2 4 m / b^2 ~ 1e-5 rad^2) would put it at 30 sigma.
  LiftedLeg leg;
  auto clean = leg.run(false, false);
  auto lifted = leg.run(false, true);
  clean->drive(0.0);
  lifted->drive(0.0);
  // The lifted wheel's part: the difference of the two runs (the same radii and noise draws, the
  // clean run's error is the wheels' radius tolerance).
  const double e = std::fabs(lifted->error().theta);
  EXPECT_NEAR(lifted->error().theta - clean->error().theta, 0.093, 0.003);
  const double var = lifted->loop().odometry().covariance()[8];
  const double var_clean = clean->loop().odometry().covariance()[8];
  EXPECT_GT(var, e * e);
  EXPECT_NEAR(var, 0.0347 + var_clean, 0.01);
  EXPECT_LT(var_clean, 1e-4);
  EXPECT_EQ(lifted->loop().snapshot().encoder_counters.slip_events, 1u);
  EXPECT_EQ(clean->loop().snapshot().encoder_counters.slip_events, 0u);
  std::printf(
      "lifted 1 s: heading error %.4f rad (clean run %.4f), heading sigma %.4f rad (clean %.2e)\n",
      e, clean->error().theta, std::sqrt(var), std::sqrt(var_clean));
}

TEST(SideWheelsLoop, WithAGyroTheSlipTakesTheGyrosHeading) {
  // With a gyro the lifted wheel's heading error (0.1 rad) is replaced by the gyro's view: the
  // gyro's own disagreement and the slip flag both open the interval (whichever comes first
  // counts the event).
  LiftedLeg leg;
  auto plain = leg.run(false, true);
  auto fused = leg.run(true, true);
  plain->drive(0.0);
  fused->drive(0.0);
  const double e_plain = std::fabs(plain->error().theta);
  const double e_fused = std::fabs(fused->error().theta);
  const Gyrodometry* g = fused->loop().fusion();
  ASSERT_NE(g, nullptr);
  EXPECT_GE(g->counters().slip_events + g->counters().disagreements, 1u);
  EXPECT_GT(g->counters().gyro_used_ticks, 0u);
  EXPECT_LT(e_fused, e_plain / 10.0);
  std::printf("lifted 1 s: heading error odometry %.4f rad, with the gyro %.2e rad\n", e_plain,
              e_fused);
}

TEST(SideWheelsLoop, SlipFlagAloneOpensTheGyrosInterval) {
  // Wheel 0 of both sides lifted at once: both sides over-count alike, the heading hardly moves
  // and the gyro sees no disagreement; only the slip flags tell. They force the gyro's heading
  // (the fusion counts slip events, no disagreement), and the heading stays as good as without.
  LiftedLeg leg;
  auto fused = leg.run(true, true, true);
  fused->drive(0.0);
  const Gyrodometry* g = fused->loop().fusion();
  ASSERT_NE(g, nullptr);
  EXPECT_GE(g->counters().slip_events, 1u);
  EXPECT_EQ(g->counters().disagreements, 0u);
  EXPECT_GT(g->counters().gyro_used_ticks, 0u);
  EXPECT_EQ(fused->loop().snapshot().encoder_counters.slip_events, 2u);
  EXPECT_LT(std::fabs(fused->error().theta), 0.01);
}

}  // namespace
}  // namespace odo::sim
