// Gyrodometry fusion: hand-derived thresholds, bias and scale estimation, coarse-encoder
// quantisation, bump replacement, kinematic limits, gyro faults and the gyro covariance.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>

#include "odo/odometry/error_model.hpp"
#include "odo/odometry/gyrodometry.hpp"
#include "odo/odometry/pose.hpp"

namespace odo {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kB = 0.34;      // wheelbase [m]
constexpr double kTick = 0.005;  // 200 Hz
// LabMate: 2048 cpr x 16 gear on a 0.15 m wheel: m = pi 0.15 / 32768 = 1.43811e-5 m;
// q = 2 m / b = 8.459453e-5 rad. Direct drive (no gear): m = 2.300971e-4 m, q = 1.353512e-3 rad.
constexpr double kQLabMate = 8.459452874369344e-05;
constexpr double kMDirect = 2.3009711818284618e-04;
constexpr double kQDirect = 1.353512459899095e-03;

GyrodometryParams params(double q) {
  GyrodometryParams p;
  p.noise.rate_noise_density = 0.014 * kPi / 180.0;       // 2.443461e-4 rad/s/sqrt(Hz)
  p.noise.bias_instability = 2.0 * kPi / 180.0 / 3600.0;  // 9.696274e-6 rad/s
  p.noise.scale_tolerance = 0.01;
  p.tick = kTick;
  p.window = 0.1;
  p.k_sigma = 5.0;
  p.heading_quantum = q;
  p.still_time = 0.5;
  p.gyro_delay = 0.0;             // these tests' gyro is not delayed (DelayedGyro* below is)
  p.odometry_noise = {0.0, 0.0};  // nor is odometry noisy (OdometryNoise* below is)
  return p;
}

FusionInput input(double d_left, double d_right, double rate, std::uint32_t flags = kGyroOk) {
  FusionInput in;
  in.dt = kTick;
  in.d_left = d_left;
  in.d_right = d_right;
  in.wheelbase = kB;
  in.gyro.rate_z = rate;
  in.gyro.flags = flags;
  in.gyro.samples = 5;
  return in;
}

// learn_bias: 201 ticks of standstill at gyro rate `bias`: still_time = 0.5 s is reached on the
// 100th tick (100 additions of 0.005 give 0.5000000000000003), so ticks 100..201 are averaged:
// bias_time = 102 * 0.005 = 0.51 s.
void learn_bias(Gyrodometry& g, double bias) {
  for (int i = 0; i < 201; ++i) g.step(input(0.0, 0.0, bias));
  ASSERT_TRUE(g.bias_valid());
}

TEST(Gyrodometry, WindowIsTwentyTicksAndThresholdIsHandDerived) {
  auto g = Gyrodometry::create(params(kQLabMate)).value();
  EXPECT_EQ(g.window_ticks(), 20u);  // 0.1 s / 0.005 s
  learn_bias(g, 0.0);
  // T = q + k N sqrt(T_w) + (B + N / sqrt(0.51 s)) T_w + s_tol |sum odo| with sum odo = 0:
  //   5 * 2.443461e-4 * sqrt(0.1)                 = 3.863451e-4
  //   (9.696274e-6 + 2.443461e-4 / 0.7141428) 0.1 = (9.696274e-6 + 3.421536e-4) 0.1 = 3.518499e-5
  //   LabMate: 8.459453e-5 + 3.863451e-4 + 3.518499e-5 = 5.061246e-4
  EXPECT_NEAR(g.threshold(), 5.061246e-4, 1e-9);
  auto d = Gyrodometry::create(params(kQDirect)).value();
  learn_bias(d, 0.0);
  // Direct drive: 1.353512e-3 + 3.863451e-4 + 3.518499e-5 = 1.775042e-3
  EXPECT_NEAR(d.threshold(), 1.775042e-3, 1e-9);
}

TEST(Gyrodometry, BiasLearnedAtStandstillOnly) {
  auto g = Gyrodometry::create(params(kQLabMate)).value();
  // 1 deg/s offset = 0.01745329 rad/s. The first 99 ticks only confirm the standstill (still_time
  // is reached on the 100th, see learn_bias).
  const double bias = kPi / 180.0;
  for (int i = 0; i < 99; ++i) {
    const FusedTick t = g.step(input(0.0, 0.0, bias));
    EXPECT_TRUE(t.flags & kFusionNoBias);
    EXPECT_TRUE(t.flags & kFusionStill);
    EXPECT_EQ(t.dtheta, 0.0);
  }
  EXPECT_EQ(g.bias(), 0.0);
  // Averaging: the first averaged sample sets b = 0 + (r - 0) dt / dt = r exactly; a running
  // mean of a constant stays it.
  for (int i = 0; i < 99; ++i) {
    g.step(input(0.0, 0.0, bias));
    EXPECT_FALSE(g.bias_valid()) << i;  // 0.5 s of averaging are needed
  }
  g.step(input(0.0, 0.0, bias));  // the 100th averaged tick (0.5000000000000003 s again)
  EXPECT_TRUE(g.bias_valid());
  EXPECT_NEAR(g.bias(), bias, 1e-17);
  // Moving: the bias is not touched even though the gyro reads something else.
  for (int i = 0; i < 50; ++i) g.step(input(0.001, 0.001, 5.0 * bias));
  EXPECT_NEAR(g.bias(), bias, 1e-17);
}

TEST(Gyrodometry, NoBiasMeansOdometryOnly) {
  auto g = Gyrodometry::create(params(kQLabMate)).value();
  // Moving from the start: no standstill, no bias, so odometry's increment even when the gyro
  // disagrees by a lot (it could be its 5 deg/s offset).
  for (int i = 0; i < 100; ++i) {
    const FusedTick t = g.step(input(0.001, 0.0011, 0.0));
    EXPECT_EQ(t.dtheta, (0.0011 - 0.001) / kB);
    EXPECT_EQ(t.flags & kFusionGyroUsed, 0u);
    EXPECT_TRUE(t.flags & kFusionNoBias);
  }
  EXPECT_EQ(g.counters().disagreements, 0u);
}

TEST(Gyrodometry, CoarseEncoderTurnIsNeverFlagged) {
  // Direct drive, 2048 cpr, turning on the spot at 0.05 rad/s: each wheel moves
  // 0.05 * 0.34/2 = 0.0085 m/s = 4.25e-5 m = 0.1847 counts a tick. Odometry's heading comes in
  // steps of m/b = 6.767e-4 rad (one wheel's count) while the gyro says 2.5e-4 rad every tick.
  auto g = Gyrodometry::create(params(kQDirect)).value();
  learn_bias(g, 0.003);
  const double w = 0.05, v = w * kB / 2.0;
  double fused = 0.0, odo = 0.0, max_tick_gap = 0.0;
  std::int64_t prev_l = 0, prev_r = 0;
  for (int i = 1; i <= 4000; ++i) {  // 20 s
    const double travel = v * kTick * i;
    // Both wheels' encoders start half a count from a boundary (as SimRobot's do).
    const auto cl = static_cast<std::int64_t>(std::floor(-travel / kMDirect + 0.5));
    const auto cr = static_cast<std::int64_t>(std::floor(travel / kMDirect + 0.5));
    const double dl = static_cast<double>(cl - prev_l) * kMDirect;
    const double dr = static_cast<double>(cr - prev_r) * kMDirect;
    prev_l = cl;
    prev_r = cr;
    const FusedTick t = g.step(input(dl, dr, w + 0.003));
    ASSERT_EQ(t.flags & kFusionGyroUsed, 0u) << "tick " << i;
    fused += t.dtheta;
    odo += t.dtheta_odo;
    max_tick_gap = std::max(max_tick_gap, std::fabs(t.dtheta_odo - w * kTick));
  }
  // The window never flags, so the fused heading is odometry's, to the last bit.
  EXPECT_EQ(fused, odo);
  EXPECT_EQ(g.counters().disagreements, 0u);
  // Per tick the disagreement reaches m/b - w dt = 6.767e-4 - 2.5e-4 = 4.27e-4 rad (a count
  // arriving) while the per-tick gyro noise term is 5 N sqrt(0.005) = 8.64e-5: a tick-by-tick
  // rule would have flagged it, a window of counts does not.
  EXPECT_GT(max_tick_gap, 4.2e-4);
  EXPECT_GT(max_tick_gap, 4.0 * 8.64e-5);
}

TEST(Gyrodometry, BumpReplacedOverTheWholeInterval) {
  // LabMate at 0.2 m/s: 1 mm per tick on both wheels, heading 0, gyro exact (bias 0.01 rad/s).
  // A bump under the left wheel over 20 ticks (0.1 s) over-counts 0.13 mm a tick: odometry's
  // heading drops by 20 * 1.3e-4 / 0.34 = 7.647059e-3 rad (0.44 deg). Per tick the disagreement
  // is 3.8235e-4, so the window crosses T = 5.0646e-4 on the bump's second tick; the correction
  // then replaces both ticks, the interval runs until the window holds at most one bump tick,
  // and every bump tick ends up with the gyro's increment 0: the fused heading stays 0.
  // The correction, 7.647059e-3 rad, is b c = 2.6e-3 m of one wheel's travel; only the left
  // wheel, moving forward, can have over-counted it (the right would have to be 2.6 mm short), so
  // the centre travel loses half of it: -1.3e-3 m, the bump's 20 * 0.13 mm / 2.
  auto g = Gyrodometry::create(params(kQLabMate)).value();
  learn_bias(g, 0.01);
  double fused = 0.0, odo = 0.0, var = 0.0, ds = 0.0;
  int used = 0, starts = 0;
  for (int i = 0; i < 200; ++i) {
    const bool bump = i >= 50 && i < 70;
    const FusedTick t = g.step(input(bump ? 0.00113 : 0.001, 0.001, 0.01));
    fused += t.dtheta;
    odo += t.dtheta_odo;
    var += t.var_heading;
    ds += t.ds;
    used += (t.flags & kFusionGyroUsed) != 0;
    starts += (t.flags & kFusionEventStart) != 0;
    if (i == 51) {
      EXPECT_TRUE(t.flags & kFusionEventStart);
    }
  }
  EXPECT_NEAR(odo, -7.647059e-3, 1e-9);
  EXPECT_NEAR(fused, 0.0, 1e-15);
  EXPECT_NEAR(ds, -1.3e-3, 1e-15);
  EXPECT_EQ(starts, 1);
  EXPECT_EQ(g.counters().disagreements, 1u);
  // Interval: from tick 51 while the window holds 2+ bump ticks (2 * 3.8235e-4 > T), i.e. up to
  // tick 87 (window 68..87): ticks 51..87 are flagged, 37 of them. On tick 51 the whole window
  // (ticks 32..51) takes the gyro's increments, identical to odometry's on the 18 ticks before the
  // bump: 20 + 36 = 56 ticks of gyro heading.
  EXPECT_EQ(used, 37);
  EXPECT_EQ(g.counters().gyro_used_ticks, 56u);
  EXPECT_FALSE(g.in_interval());
  // Heading variance of 56 gyro ticks, T = 0.28 s: N^2 T + b_res^2 T^2 (the per-tick bias terms
  // b_res^2 dt^2 (2k + 1) add up to b_res^2 (n dt)^2), b_res = 3.518499e-4 (learn_bias):
  //   5.970501e-8 * 0.28 + 1.237983e-7 * 0.0784 = 1.671740e-8 + 9.705787e-9 = 2.642319e-8
  EXPECT_NEAR(var, 2.642319e-8, 1e-13);
}

// After a restart mid-drive (the loop's state record): the restored calibration detects the
// bump of BumpReplacedOverTheWholeInterval at once; a fresh fusion has no bias and cannot.
TEST(Gyrodometry, RestoredCalibrationDetectsAtOnce) {
  auto before = Gyrodometry::create(params(kQLabMate)).value();
  learn_bias(before, 0.01);
  const GyroCalibration c = before.calibration();
  EXPECT_NEAR(c.bias_time, 0.51, 1e-12);  // 102 averaged ticks of 0.005 s (learn_bias)
  EXPECT_NEAR(c.bias, 0.01, 1e-17);
  auto restored = Gyrodometry::create(params(kQLabMate)).value();
  auto fresh = Gyrodometry::create(params(kQLabMate)).value();
  EXPECT_TRUE(restored.restore(c));
  // Same bias, same averaging time, so the same B_res: the threshold of
  // WindowIsTwentyTicksAndThresholdIsHandDerived, 5.061246e-4 rad.
  EXPECT_NEAR(restored.threshold(), 5.061246e-4, 1e-9);
  double fused_r = 0.0, fused_f = 0.0, odo = 0.0;
  for (int i = 0; i < 200; ++i) {
    const bool bump = i >= 50 && i < 70;
    const FusionInput in = input(bump ? 0.00113 : 0.001, 0.001, 0.01);
    const FusedTick r = restored.step(in);
    const FusedTick f = fresh.step(in);
    EXPECT_EQ(r.flags & kFusionNoBias, 0u) << i;
    EXPECT_NE(f.flags & kFusionNoBias, 0u) << i;
    fused_r += r.dtheta;
    fused_f += f.dtheta;
    odo += r.dtheta_odo;
  }
  EXPECT_NEAR(odo, -7.647059e-3, 1e-9);  // the bump's heading error (see the test above)
  EXPECT_NEAR(fused_r, 0.0, 1e-15);
  EXPECT_EQ(restored.counters().disagreements, 1u);
  EXPECT_EQ(fused_f, odo);  // without a bias: odometry alone, the bump kept
  EXPECT_EQ(fresh.counters().disagreements, 0u);
}

TEST(Gyrodometry, RestoreKeepsTheEstimatorsOwnLimits) {
  GyrodometryParams p = params(kQLabMate);
  p.bias_tau = 60.0;
  p.scale_max_error = 0.05;
  auto g = Gyrodometry::create(p).value();
  // Averaged longer than bias_tau: capped at it, as update_bias caps it.
  EXPECT_TRUE(g.restore({2e-3, 1000.0, 1.0, false}));
  EXPECT_EQ(g.calibration().bias_time, 60.0);
  EXPECT_FALSE(g.scale_valid());
  // Averaged for less than still_time (0.5 s): kept as 0.25 s of averaging, but not yet valid.
  auto s = Gyrodometry::create(p).value();
  EXPECT_FALSE(s.restore({2e-3, 0.25, 1.0, false}));
  EXPECT_FALSE(s.bias_valid());
  EXPECT_EQ(s.calibration().bias_time, 0.25);
  // Scales: 1.04 is within 1 +- 0.05 and applied; 1.06 is not, nor is a NaN or a bias that was
  // never learnt (bias_time 0).
  auto k = Gyrodometry::create(p).value();
  EXPECT_FALSE(k.restore({0.0, 0.0, 1.06, true}));
  EXPECT_FALSE(k.scale_valid());
  EXPECT_EQ(k.scale(), 1.0);
  k.restore({0.0, 0.0, 1.04, true});
  EXPECT_TRUE(k.scale_valid());
  EXPECT_EQ(k.scale(), 1.04);
  auto n = Gyrodometry::create(p).value();
  EXPECT_FALSE(n.restore({std::numeric_limits<double>::quiet_NaN(), 10.0, 1.0, false}));
  EXPECT_EQ(n.bias(), 0.0);
  EXPECT_EQ(n.calibration().bias_time, 0.0);
}

TEST(Gyrodometry, WheelSpeedBeyondLimitFlagsASlip) {
  auto g = Gyrodometry::create(params(kQLabMate)).value();
  learn_bias(g, 0.0);
  for (int i = 0; i < 40; ++i) g.step(input(0.001, 0.001, 0.0));
  // One tick with the left wheel at 0.012 m / 0.005 s = 2.4 m/s (limit 2 m/s): the heading of
  // that tick is the gyro's 0 instead of odometry's -0.011/0.34.
  const FusedTick t = g.step(input(0.012, 0.001, 0.0));
  EXPECT_TRUE(t.flags & kFusionSpeedLimit);
  EXPECT_TRUE(t.flags & kFusionGyroUsed);
  EXPECT_NEAR(t.dtheta, 0.0, 1e-18);
  EXPECT_EQ(g.counters().speed_events, 1u);
}

TEST(Gyrodometry, WheelSlipFlagForcesTheGyrosHeading) {
  // The left wheel 0.01 mm ahead on one tick: odometry's heading -1e-5 / 0.34 = -2.94e-5 rad,
  // far below the threshold (5.06e-4 rad standing, see the top): unflagged, odometry's own.
  auto g = Gyrodometry::create(params(kQLabMate)).value();
  learn_bias(g, 0.0);
  for (int i = 0; i < 40; ++i) g.step(input(0.001, 0.001, 0.0));
  const FusedTick quiet = g.step(input(0.00101, 0.001, 0.0));
  EXPECT_EQ(quiet.flags & kFusionGyroUsed, 0u);
  EXPECT_EQ(quiet.dtheta, quiet.dtheta_odo);
  // The same tick with the encoders' slip flag (two wheels of a side disagree): the gyro's
  // heading, 0, for it; the interval replaces the window's ticks, whose errors are 0 but this
  // one's, so the correction is exactly -dtheta_odo.
  auto h = Gyrodometry::create(params(kQLabMate)).value();
  learn_bias(h, 0.0);
  for (int i = 0; i < 40; ++i) h.step(input(0.001, 0.001, 0.0));
  FusionInput in = input(0.00101, 0.001, 0.0);
  in.slip = true;
  const FusedTick t = h.step(in);
  EXPECT_TRUE(t.flags & kFusionWheelSlip);
  EXPECT_TRUE(t.flags & kFusionGyroUsed);
  EXPECT_NEAR(t.dtheta, 0.0, 1e-18);
  EXPECT_EQ(h.counters().slip_events, 1u);
  EXPECT_EQ(h.counters().disagreements, 0u);
}

TEST(Gyrodometry, AccelerationFromHalfWindows) {
  // Accelerating both wheels at 12 m/s^2 (limit 10): the halves' mean speeds differ by
  // a T_h = 12 * 0.05 = 0.6 m/s, i.e. 0.03 m of half-window travel > 10 * 0.05^2 = 0.025 m.
  auto g = Gyrodometry::create(params(kQLabMate)).value();
  learn_bias(g, 0.0);
  bool flagged = false;
  for (int i = 1; i <= 20 && !flagged; ++i) {
    const double d = 12.0 * kTick * kTick * i;  // v = a t, d = v dt
    flagged = (g.step(input(d, d, 0.0)).flags & kFusionAccelLimit) != 0;
  }
  EXPECT_TRUE(flagged);
  EXPECT_EQ(g.counters().accel_events, 1u);
  // 8 m/s^2 stays quiet.
  auto h = Gyrodometry::create(params(kQLabMate)).value();
  learn_bias(h, 0.0);
  for (int i = 1; i <= 60; ++i) {
    const double d = 8.0 * kTick * kTick * i;
    EXPECT_EQ(h.step(input(d, d, 0.0)).flags & kFusionAccelLimit, 0u) << i;
  }
}

TEST(Gyrodometry, FaultyGyroFallsBackToOdometry) {
  auto g = Gyrodometry::create(params(kQLabMate)).value();
  learn_bias(g, 0.0);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  struct Case {
    double rate;
    std::uint32_t flags;
  };
  // NaN without a flag, a stale sample, a saturated one, a read error.
  const Case cases[] = {{nan, kGyroOk},
                        {0.0, kGyroStale},
                        {34.9, kGyroSaturated},
                        {0.0, kGyroReadError},
                        {std::numeric_limits<double>::infinity(), 0}};
  std::uint64_t faults = 0;
  for (const Case& c : cases) {
    // In the middle of a bump (odometry turning, gyro quiet) and for 5 ticks.
    for (int i = 0; i < 5; ++i) {
      const FusedTick t = g.step(input(0.0012, 0.001, c.rate, c.flags));
      EXPECT_TRUE(t.flags & kFusionGyroFault);
      EXPECT_EQ(t.flags & kFusionGyroUsed, 0u);
      EXPECT_EQ(t.dtheta, (0.001 - 0.0012) / kB);
      EXPECT_TRUE(std::isfinite(t.dtheta));
    }
    ++faults;
    EXPECT_EQ(g.counters().gyro_faults, faults);  // one event per run of faulty samples
    // Back to good samples: windows holding a faulty tick are not compared, so nothing is
    // flagged for 20 ticks even though odometry disagrees with the gyro by 5.9e-4 a tick.
    for (int i = 0; i < 19; ++i) {
      EXPECT_EQ(g.step(input(0.0012, 0.001, 0.0)).flags & kFusionGyroUsed, 0u) << i;
    }
    // Once the faulty ticks have left the window, the 19 good disagreeing ticks in it are
    // detected (19 * 5.88e-4 rad > T) and replaced: one event per case.
    for (int i = 0; i < 40; ++i) g.step(input(0.001, 0.001, 0.0));
    EXPECT_EQ(g.counters().disagreements, faults);
  }
}

// A gyro still starting (kGyroStarting: no sample yet, within its timeout) is not used and is
// no fault; the same gyro going stale without ever delivering is one fault, and so is a failure
// after it has worked. Bias learning waits for usable samples: the standstill's still_time runs
// from the first tick (0.5 s = 100 ticks), but only ticks with a usable rate are averaged.
TEST(Gyrodometry, StartingGyroIsNotAFault) {
  auto g = Gyrodometry::create(params(kQLabMate)).value();
  for (int i = 0; i < 150; ++i) {
    const FusedTick t = g.step(input(0.0, 0.0, 0.0, kGyroStarting));
    EXPECT_TRUE(t.flags & kFusionGyroFault);  // not used: odometry alone
    EXPECT_EQ(t.flags & kFusionGyroUsed, 0u);
  }
  EXPECT_EQ(g.counters().gyro_faults, 0u);
  EXPECT_FALSE(g.bias_valid());  // no usable sample yet, though still for 0.75 s
  // The first samples arrive: ticks 151..250 are averaged (the standstill is long confirmed);
  // the bias is valid once 0.5 s of them are (tick 250).
  for (int i = 0; i < 100; ++i) g.step(input(0.0, 0.0, 1e-3));
  EXPECT_TRUE(g.bias_valid());
  EXPECT_NEAR(g.bias(), 1e-3, 1e-15);
  EXPECT_EQ(g.counters().gyro_faults, 0u);
  // It goes stale: the first fault. A source never reports starting again after a sample; were
  // it to, that would not end the run of faults (no second count) as a usable sample does.
  g.step(input(0.0, 0.0, 0.0, kGyroStale));
  EXPECT_EQ(g.counters().gyro_faults, 1u);
  g.step(input(0.0, 0.0, 0.0, kGyroStarting));
  g.step(input(0.0, 0.0, 0.0, kGyroStale));
  EXPECT_EQ(g.counters().gyro_faults, 1u);
  // A source that never delivers: starting, then stale at its timeout: one fault.
  auto h = Gyrodometry::create(params(kQLabMate)).value();
  for (int i = 0; i < 10; ++i) h.step(input(0.0, 0.0, 0.0, kGyroStarting));
  for (int i = 0; i < 10; ++i) h.step(input(0.0, 0.0, 0.0, kGyroStale));
  EXPECT_EQ(h.counters().gyro_faults, 1u);
}

TEST(Gyrodometry, FaultDuringIntervalEndsIt) {
  auto g = Gyrodometry::create(params(kQLabMate)).value();
  learn_bias(g, 0.0);
  for (int i = 0; i < 40; ++i) g.step(input(0.001, 0.001, 0.0));
  for (int i = 0; i < 3; ++i) g.step(input(0.0015, 0.001, 0.0));
  ASSERT_TRUE(g.in_interval());
  const FusedTick t = g.step(input(0.0015, 0.001, 0.0, kGyroStale));
  EXPECT_FALSE(g.in_interval());
  EXPECT_EQ(t.dtheta, (0.001 - 0.0015) / kB);
}

TEST(Gyrodometry, ScaleFactorFromTurns) {
  // The gyro reads 0.5 % high: while turning at 0.5 rad/s its window exceeds odometry's by
  // 0.005 * 0.05 = 2.5e-4 rad, under T = 5.06e-4 + 0.01 * 0.05, so nothing is flagged. After
  // 2 pi of turns the estimate is sum odo / sum gyro = 1/1.005 (exact inputs: no quantisation).
  auto g = Gyrodometry::create(params(kQLabMate)).value();
  g.set_scale_estimation(true);
  learn_bias(g, 0.02);
  const double w = 0.5, d = w * kB / 2.0 * kTick;
  for (int i = 0; i < 2600 && !g.scale_valid(); ++i) {  // 2 pi at 0.5 rad/s: 12.57 s, 2514 ticks
    g.step(input(-d, d, 1.005 * w + 0.02));
  }
  ASSERT_TRUE(g.scale_valid());
  EXPECT_NEAR(g.scale(), 1.0 / 1.005, 1e-12);
  EXPECT_EQ(g.counters().disagreements, 0u);
}

// A gyro whose samples lag the motion by 2 ms, read at 100 Hz: m = ceil(0.2) = 1 tick, g = 0.8.
// The robot turns on the spot at w = 0.5 rad/s from tick 1 to tick 300 (the rate steps at tick
// boundaries), exact odometry. Gyro tick j (ending at 10 j ms) covers the motion of
// [10 j - 12, 10 j - 2] ms: tick 1 sees 8 ms of turning, 0.8 w dt; ticks 2..300 see w dt; tick 301
// sees 2 ms, 0.2 w dt. The aligned increment compared with odometry's tick j - 1 is
// 0.2 gyro_j + 0.8 gyro_j-1.
//   tick 1: E = 0.2 * 0.8 w dt - odo_0 = 0.16 w dt = 8e-4 rad (w dt = 5e-3): the interpolation
//           point (2 ms into gyro tick 1) is the step itself, p = 1 - g = 0.2, s = 0.2:
//           error p (1 - s) w dt. The bound e_new = p J_old = 0.2 * |0.8 w dt - 0| is the same
//           8e-4, and the delay term adds delta_d / tick |gyro_0 - gyro_n| = 0.05 * 0.8 w dt =
//           2e-4: T - T_still = 1e-3 (the scale term is 0: odometry's compared tick, tick 0, is
//           still).
//   tick 2: err = 0.2 w dt + 0.8 * 0.8 w dt - w dt = -0.16 w dt: E = 0 (the sum telescopes).
// Every window is within its threshold; the old comparison of the same ticks (no re-timing) sees
// 0.8 w dt - w dt = -1e-3 against T = T_still + 2.5e-4 and flags the turn's start.
GyrodometryParams delayed_params(double delay) {
  GyrodometryParams p = params(kQLabMate);
  p.tick = 0.01;
  p.gyro_delay = delay;
  p.delay_tolerance = 0.0005;
  return p;
}

FusionInput input_at(double dt, double d_left, double d_right, double rate) {
  FusionInput in = input(d_left, d_right, rate);
  in.dt = dt;
  return in;
}

TEST(Gyrodometry, DelayedGyroTurnIsNeverFlagged) {
  const double w = 0.5, dt = 0.01, d = w * kB / 2.0 * dt, bias = 0.01;
  auto g = Gyrodometry::create(delayed_params(0.002)).value();
  EXPECT_EQ(g.delay_ticks(), 1u);
  EXPECT_NEAR(g.gyro_weight(), 0.8, 1e-12);
  for (int i = 0; i < 101; ++i) g.step(input_at(dt, 0.0, 0.0, bias));  // 0.5 s still + 0.51 s
  ASSERT_TRUE(g.bias_valid());
  for (int i = 0; i < 20; ++i) g.step(input_at(dt, 0.0, 0.0, bias));
  const double t_still = g.threshold();
  double fused = 0.0, odo = 0.0;
  for (int j = 1; j <= 400; ++j) {
    const bool turning = j <= 300;
    const double seen = j == 1 ? 0.8 : (j <= 300 ? 1.0 : (j == 301 ? 0.2 : 0.0));
    const FusedTick t =
        g.step(input_at(dt, turning ? -d : 0.0, turning ? d : 0.0, seen * w + bias));
    ASSERT_EQ(t.flags & kFusionGyroUsed, 0u) << "tick " << j;
    fused += t.dtheta;
    odo += t.dtheta_odo;
    if (j == 1) {
      EXPECT_NEAR(g.disagreement(), 8e-4, 1e-15);
      EXPECT_NEAR(g.threshold() - t_still, 1e-3, 1e-15);
    }
    if (j == 2) {
      EXPECT_NEAR(g.disagreement(), 0.0, 1e-15);
    }
  }
  EXPECT_EQ(fused, odo);
  EXPECT_EQ(g.counters().disagreements, 0u);

  // The same gyro, taken as undelayed: the turn's start is a disagreement.
  auto u = Gyrodometry::create(delayed_params(0.0)).value();
  for (int i = 0; i < 121; ++i) u.step(input_at(dt, 0.0, 0.0, bias));
  for (int j = 1; j <= 5; ++j) {
    const double seen = j == 1 ? 0.8 : 1.0;
    u.step(input_at(dt, -d, d, seen * w + bias));
  }
  EXPECT_EQ(u.counters().disagreements, 1u);
}

TEST(Gyrodometry, KinematicLimitTickIsReplacedOnceTheGyroCatchesUp) {
  // 200 Hz, delay 2 ms: m = 1, g = 0.6. One tick with the left wheel at 2.4 m/s (limit 2 m/s),
  // gyro exact (0 rate): on that tick the gyro's view of it is not there yet (its err compares
  // odometry's previous tick, 0), so it integrates odometry's -0.011/0.34 = -0.032353 rad; the
  // interval holds one more tick, whose err = 0 - (-0.032353) puts it back: the two ticks sum
  // to the gyro's 0.
  GyrodometryParams p = params(kQLabMate);
  p.gyro_delay = 0.002;
  auto g = Gyrodometry::create(p).value();
  learn_bias(g, 0.0);
  for (int i = 0; i < 40; ++i) g.step(input(0.001, 0.001, 0.0));
  const FusedTick spike = g.step(input(0.012, 0.001, 0.0));
  EXPECT_TRUE(spike.flags & kFusionSpeedLimit);
  EXPECT_NEAR(spike.dtheta, -0.011 / kB, 1e-15);
  const FusedTick next = g.step(input(0.001, 0.001, 0.0));
  EXPECT_TRUE(next.flags & kFusionGyroUsed);
  EXPECT_NEAR(spike.dtheta + next.dtheta, 0.0, 1e-15);
  EXPECT_EQ(g.counters().speed_events, 1u);
}

// Odometry's own noise (Chong-Kleeman k_L = 4.0e-4, k_R = 5.8e-4 m^(1/2), the error model's
// defaults) enters the threshold: a floor's small bumps are odometry noise, not events. Straight
// at 1 mm a tick on both wheels, 20-tick window: odometry's heading variance over the window is
// (k_L^2 + k_R^2) 0.02 m / b^2 = (1.6e-7 + 3.364e-7) 0.02 / 0.1156 = 8.588235e-8 rad^2, the gyro's
// N^2 T_w = 5.970501e-9; 5 sqrt(9.185285e-8) = 1.515362e-3, so
//   T = q + B_res T_w + 1.515362e-3 = 8.459453e-5 + 3.518492e-5 + 1.515362e-3 = 1.635141e-3 rad.
// A 0.4 mm loss under one wheel (1.176e-3 rad) stays below it; the bump of
// BumpReplacedOverTheWholeInterval (3.8235e-4 rad a tick) is flagged once 5 of its ticks are in
// the window (1.912e-3 > T = 1.66e-3; 4 ticks give 1.529e-3).
TEST(Gyrodometry, OdometryNoiseRaisesTheThreshold) {
  GyrodometryParams p = params(kQLabMate);
  p.odometry_noise = {4.0e-4, 5.8e-4};
  auto g = Gyrodometry::create(p).value();
  learn_bias(g, 0.0);
  for (int i = 0; i < 40; ++i) g.step(input(0.001, 0.001, 0.0));
  EXPECT_NEAR(g.threshold(), 1.635141e-3, 1e-9);
  g.step(input(0.0006, 0.001, 0.0));  // the small bump: odometry turns by 1.176e-3 rad
  for (int i = 0; i < 40; ++i) g.step(input(0.001, 0.001, 0.0));
  EXPECT_EQ(g.counters().disagreements, 0u);
  double fused = 0.0;
  int first = -1;
  for (int i = 0; i < 100; ++i) {
    const bool bump = i >= 50 && i < 70;
    const FusedTick t = g.step(input(bump ? 0.00113 : 0.001, 0.001, 0.0));
    fused += t.dtheta;
    if (first < 0 && (t.flags & kFusionEventStart)) first = i;
  }
  EXPECT_EQ(first, 54);
  EXPECT_EQ(g.counters().disagreements, 1u);
  EXPECT_NEAR(fused, 0.0, 1e-15);
  // Without odometry's noise the small bump alone is an event (1.176e-3 > 5.06e-4).
  auto h = Gyrodometry::create(params(kQLabMate)).value();
  learn_bias(h, 0.0);
  for (int i = 0; i < 40; ++i) h.step(input(0.001, 0.001, 0.0));
  h.step(input(0.0006, 0.001, 0.0));
  EXPECT_EQ(h.counters().disagreements, 1u);
}

TEST(Gyrodometry, RejectsBadParameters) {
  GyrodometryParams p = params(kQLabMate);
  p.window = std::numeric_limits<double>::quiet_NaN();
  auto r = Gyrodometry::create(p);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().message.find("window"), std::string::npos) << r.error().message;
  p = params(kQLabMate);
  p.bias_tau = 0.1;  // shorter than still_time
  r = Gyrodometry::create(p);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().message.find("bias_tau"), std::string::npos) << r.error().message;
}

TEST(Gyrodometry, FusedUpdateIsOdometryWhenNothingIsFlagged) {
  // The loop integrates FusedTick::dtheta with Odometry::update_fused. When the fusion passes
  // odometry's own increment through, the pose must be bit-identical to update()'s.
  const Kinematics k = Kinematics::create({0.15, 2048, 16, 0.34, 0.34, 1.0, 1.0}).value();
  Odometry plain(k), fused(k);
  auto g = Gyrodometry::create(params(kQLabMate)).value();
  std::uint64_t x = 12345;
  for (int i = 0; i < 5000; ++i) {
    x = x * 6364136223846793005ull + 1442695040888963407ull;  // LCG: counts -3..+12 per tick
    const std::int64_t dl = static_cast<std::int64_t>((x >> 33) % 16) - 3;
    const std::int64_t dr = static_cast<std::int64_t>((x >> 45) % 16) - 3;
    FusionInput in = input(static_cast<double>(dl) * k.metres_per_count_left(),
                           static_cast<double>(dr) * k.metres_per_count_right(), 0.0);
    in.gyro.flags = kGyroStale;  // odometry only
    const FusedTick t = g.step(in);
    plain.update(dl, dr, kTick);
    fused.update_fused(dl, dr, kTick, t.dtheta, t.ds);
  }
  EXPECT_EQ(plain.pose().x, fused.pose().x);
  EXPECT_EQ(plain.pose().y, fused.pose().y);
  EXPECT_EQ(plain.pose().theta, fused.pose().theta);
  EXPECT_EQ(plain.angular_velocity(), fused.angular_velocity());
  // Another heading: straight counts, 1e-3 rad per tick from elsewhere: 100 ticks turn 0.1 rad.
  Odometry turn(k);
  for (int i = 0; i < 100; ++i) turn.update_fused(70, 70, kTick, 1e-3, 0.0);
  EXPECT_NEAR(turn.pose().theta, 0.1, 1e-15);
  EXPECT_NEAR(turn.angular_velocity(), 0.2, 1e-15);
}

enum { XX = 0, XY = 1, XT = 2, YY = 4, YT = 5, TT = 8 };

TEST(GyroCovariance, StraightLineHandValues) {
  // ds = 2 m, no turn, var_ds = 1e-6 m^2, var_heading = 4e-6 rad^2 (derivation in
  // gyrodometry.cpp): xx = var_ds = 1e-6, yy = v D^2 / 3 = 4e-6 * 4 / 3 = 5.333333e-6,
  // yt = v D / 2 = 4e-6, tt = 4e-6, xy = xt = 0.
  Cov3 p{};
  propagate_gyro_arc(p, 0.0, 1.0, 2.0, 0.0, 1e-6, 4e-6);
  EXPECT_NEAR(p[XX], 1e-6, 1e-21);
  EXPECT_NEAR(p[YY], 16e-6 / 3.0, 1e-20);
  EXPECT_NEAR(p[YT], 4e-6, 1e-20);
  EXPECT_NEAR(p[TT], 4e-6, 1e-21);
  EXPECT_EQ(p[XY], 0.0);
  EXPECT_EQ(p[XT], 0.0);
}

TEST(GyroCovariance, EqualsChongKleemanForEqualWheels) {
  // With k_L^2 |d_L| = k_R^2 |d_R| the wheels' cross terms W- vanish, and the wheels' heading
  // noise is W+/b^2 with W+ = 2 k_L^2 |d_L|: giving the gyro exactly that heading variance must
  // reproduce Chong-Kleeman on any arc (here 0.3 m and 0.5 m: phi = 0.5882 rad, series branch;
  // and 0.1 m / 0.9 m: phi = 2.353 rad, closed forms), from any start heading.
  for (const auto& [dl, dr] : {std::pair{0.3, 0.5}, std::pair{0.1, 0.9}, std::pair{-0.2, 0.2}}) {
    // k_R^2 |d_R| = k_L^2 |d_L| makes W- = 0 on this arc.
    const ErrorModelParams k{0.0005, 0.0005 * std::sqrt(std::fabs(dl) / std::fabs(dr))};
    Cov3 ck{}, gy{};
    const double th = 0.7;
    for (int i = 0; i < 3; ++i) {  // three arcs, so the F P F^T part is exercised too
      const double t0 = th + i * (dr - dl) / kB;
      propagate_arc(ck, t0, dl, dr, kB, k);
      const double wp = 2.0 * k.k_left * k.k_left * std::fabs(dl);
      propagate_gyro_arc(gy, std::sin(t0), std::cos(t0), 0.5 * (dl + dr), (dr - dl) / kB,
                         along_track_variance(dl, dr, k), wp / (kB * kB));
    }
    for (int i = 0; i < 9; ++i) EXPECT_NEAR(gy[i], ck[i], 1e-15 * std::fabs(ck[8]) + 1e-18) << i;
  }
}

}  // namespace
}  // namespace odo
