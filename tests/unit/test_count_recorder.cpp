// CountRecorder (the loop's per-tick recording for self-calibration) and build_track.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include "odo/calibration/count_recorder.hpp"
#include "odo/calibration/selfcal.hpp"

namespace odo::calib {
namespace {

constexpr TimeNs kMs = 1'000'000;

// The reference robot's belief: 0.15 m wheels, 2048 counts, 16:1 gear, 0.34 m wheelbase.
Kinematics labmate() {
  return *Kinematics::create(KinematicParams{0.15, 2048, 16, 0.34, 0.34, 1.0, 1.0});
}

TEST(CountRecorder, LimitsInCounts) {
  // c_m = pi 0.15 / (2048 * 16) = 1.43810e-5 m/count. 1e-3 rad of turn: 1e-3 * 0.34 / c_m =
  // 23.64 -> 23 counts of N_R - N_L; 0.05 m of centre travel: 2 * 0.05 / c_m = 6953.5 -> 6953
  // counts of |N_L| + |N_R|; 20 ms.
  auto l = recorder_limits(labmate());
  ASSERT_TRUE(l) << l.error().message;
  EXPECT_EQ(l->max_turn_counts, 23);
  EXPECT_EQ(l->max_travel_counts, 6953);
  EXPECT_EQ(l->max_duration, 20 * kMs);
  EXPECT_FALSE(recorder_limits(labmate(), 0.0));
  EXPECT_FALSE(recorder_limits(labmate(), 1e-3, 1e-9));  // below one count
  EXPECT_FALSE(recorder_limits(labmate(), 1e-3, 0.05, std::nan("")));
}

TEST(CountRecorder, ClosingRules) {
  CountRecorder rec(RecorderLimits{23, 6953, 20 * kMs});
  CountSegment s;
  rec.start(0);
  // Duration: ticks of (10, 10) every 10 ms; the third tick would make the segment 30 ms long.
  EXPECT_FALSE(rec.add_tick(10 * kMs, 10, 10, s));
  EXPECT_FALSE(rec.add_tick(20 * kMs, 10, 10, s));
  ASSERT_TRUE(rec.add_tick(30 * kMs, 10, 10, s));
  EXPECT_EQ(s.t_start, 0);
  EXPECT_EQ(s.t_end, 20 * kMs);
  EXPECT_EQ(s.dn_left, 20);
  EXPECT_EQ(s.dn_right, 20);
  // Turn: the open segment is tick 30's (10, 10); (0, 10) ticks raise N_R - N_L by 10 each:
  // 10, 20 <= 23, and 30 > 23 closes (20, 32 ms] with (10, 30).
  EXPECT_FALSE(rec.add_tick(31 * kMs, 0, 10, s));
  EXPECT_FALSE(rec.add_tick(32 * kMs, 0, 10, s));
  ASSERT_TRUE(rec.add_tick(33 * kMs, 0, 10, s));
  EXPECT_EQ(s.t_start, 20 * kMs);
  EXPECT_EQ(s.t_end, 32 * kMs);
  EXPECT_EQ(s.dn_left, 10);
  EXPECT_EQ(s.dn_right, 30);
  // Reversal: open (0, 10); (-5, 5) starts the left wheel backwards from 0 (no flip), then
  // (5, 5) flips the left wheel's -5 to forwards: (32, 34 ms] closes with (-5, 15).
  EXPECT_FALSE(rec.add_tick(34 * kMs, -5, 5, s));
  ASSERT_TRUE(rec.add_tick(35 * kMs, 5, 5, s));
  EXPECT_EQ(s.t_end, 34 * kMs);
  EXPECT_EQ(s.dn_left, -5);
  EXPECT_EQ(s.dn_right, 15);
  // Standstill: the open (5, 5) closes by duration (60 - 34 > 20 ms), then zero ticks emit
  // nothing and move the next segment's start along.
  ASSERT_TRUE(rec.add_tick(60 * kMs, 0, 0, s));
  EXPECT_EQ(s.t_start, 34 * kMs);
  EXPECT_EQ(s.t_end, 35 * kMs);
  CountSegment none;
  for (int i = 7; i < 20; ++i) EXPECT_FALSE(rec.add_tick(i * 10 * kMs, 0, 0, none));
  EXPECT_FALSE(rec.add_tick(200 * kMs, 3, 3, s));
  ASSERT_TRUE(rec.flush(s));
  EXPECT_EQ(s.t_start, 190 * kMs);
  EXPECT_EQ(s.t_end, 200 * kMs);
  EXPECT_FALSE(rec.flush(s));
}

// One minute of random driving at 100 Hz (straights, arcs, spins, stops; speeds up to
// 0.3 m/s, counts quantised): integrating the recorded segments gives the same end pose as
// integrating every tick, within the documented bound sum_k 2 S_k phi_H.
TEST(CountRecorder, AggregationErrorWithinBound) {
  const Kinematics k = labmate();
  const RecorderLimits lim = *recorder_limits(k);
  const double c_m = k.metres_per_count(), b = k.wheelbase();
  const double phi_h = lim.max_turn_counts * c_m / b;
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  CountRecorder rec(lim);
  rec.start(0);
  Pose2 per_tick, per_seg;
  double bound = 0.0, wl = 0.0, wr = 0.0, acc_l = 0.0, acc_r = 0.0;
  auto take = [&](const CountSegment& s) {
    per_seg = arc_step(per_seg, c_m * s.dn_left, c_m * s.dn_right, b);
    bound += 2.0 * std::fabs(0.5 * c_m * (s.dn_left + s.dn_right)) * phi_h;
  };
  CountSegment s;
  for (int i = 1; i <= 6000; ++i) {
    if (i % 150 == 1) {  // a new piece every 1.5 s: wheel speeds [counts/tick]
      const double v = 200.0 * u(rng), w = 200.0 * u(rng);
      const int kind = static_cast<int>(4.0 * (u(rng) + 1.0) / 2.0);
      wl = kind == 0 ? v : kind == 1 ? -w : kind == 2 ? v - 0.1 * w : 0.0;
      wr = kind == 0 ? v : kind == 1 ? w : kind == 2 ? v + 0.1 * w : 0.0;
    }
    const double nl = std::floor(acc_l + wl) - std::floor(acc_l);
    const double nr = std::floor(acc_r + wr) - std::floor(acc_r);
    acc_l += wl;
    acc_r += wr;
    per_tick = arc_step(per_tick, c_m * nl, c_m * nr, b);
    if (rec.add_tick(i * 10 * kMs, static_cast<std::int64_t>(nl), static_cast<std::int64_t>(nr), s))
      take(s);
  }
  if (rec.flush(s)) take(s);
  const double err = std::hypot(per_tick.x - per_seg.x, per_tick.y - per_seg.y);
  std::printf("aggregation: position error %.3g m, bound %.3g m, heading error %.3g rad\n", err,
              bound, per_tick.theta - per_seg.theta);
  EXPECT_LE(err, bound);
  EXPECT_NEAR(per_tick.theta, per_seg.theta, 1e-12);  // the heading is linear in the counts
}

TEST(BuildTrack, SplitsSegmentsAtFixTimesInProportion) {
  // Segment (0, 10 ms] with (10, 20) counts and a fix at 4 ms: 40 % (4, 8) before it, 60 %
  // (6, 12) after; segment (10, 20 ms] (10, 10) lies wholly between fix 2 (4 ms) and fix 3
  // (25 ms); segment (20, 30 ms] is cut at 25 ms into (2.5, 2.5) and (2.5, 2.5), and the part
  // after the last fix is dropped.
  const std::vector<CountSegment> segs{
      {0, 10 * kMs, 10, 20}, {10 * kMs, 20 * kMs, 10, 10}, {20 * kMs, 30 * kMs, 5, 5}};
  const std::vector<PoseFix> fixes{{0, 0, 0, 0.0, 1e-3, 1e-3},
                                   {4 * kMs, 0, 0, 0.0, 1e-3, 1e-3},
                                   {25 * kMs, 0, 0, 0.0, 1e-3, 1e-3}};
  auto t = build_track(segs, fixes);
  ASSERT_TRUE(t) << t.error().message;
  ASSERT_EQ(t->legs.size(), 2U);
  ASSERT_EQ(t->legs[0].size(), 1U);
  EXPECT_DOUBLE_EQ(t->legs[0][0].n_left, 4.0);
  EXPECT_DOUBLE_EQ(t->legs[0][0].n_right, 8.0);
  ASSERT_EQ(t->legs[1].size(), 3U);
  EXPECT_DOUBLE_EQ(t->legs[1][0].n_left, 6.0);
  EXPECT_DOUBLE_EQ(t->legs[1][0].n_right, 12.0);
  EXPECT_DOUBLE_EQ(t->legs[1][1].n_left, 10.0);
  EXPECT_DOUBLE_EQ(t->legs[1][2].n_left, 2.5);
  // Out of order input is named.
  const std::vector<CountSegment> bad{{10 * kMs, 20 * kMs, 1, 1}, {0, 5 * kMs, 1, 1}};
  auto e = build_track(bad, fixes);
  ASSERT_FALSE(e);
  EXPECT_NE(e.error().message.find("segment 2"), std::string::npos);
}

}  // namespace
}  // namespace odo::calib
