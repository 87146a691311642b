// SideCombiner (hal/side_wheels.hpp): several encoders per side, against hand-derived numbers.
#include <gtest/gtest.h>

#include "odo/hal/side_wheels.hpp"

namespace odo {
namespace {

SideWheelsConfig two_wheels() {
  SideWheelsConfig c;
  c.wheels_per_side = 2;
  c.counter_bits = 32;
  return c;
}

SideCombiner make(const SideWheelsConfig& c) {
  auto r = SideCombiner::create(c);
  EXPECT_TRUE(r.ok()) << (r.ok() ? "" : r.error().message);
  return std::move(r).value();
}

SideReadings wheels(std::int64_t a, std::int64_t b, std::uint8_t faulted = 0) {
  SideReadings r;
  r.counts = {a, b, 0, 0};
  r.faulted = faulted;
  return r;
}

TEST(SideCombiner, MeanOfTwoWheelsRoundsTheTwelfthsOfACount) {
  SideCombiner c = make(two_wheels());
  // First read: references only, no travel.
  SideStep s = c.step(wheels(0, 0), wheels(0, 0));
  EXPECT_EQ(s.left, 0);
  EXPECT_EQ(s.flags, 0u);
  // Deltas 10 and 13: mean 11.5 = 138 twelfths; rounded (138 + 6) / 12 = 12.
  s = c.step(wheels(10, 13), wheels(5, 5));
  EXPECT_EQ(s.left, 12);
  EXPECT_EQ(s.right, 5);
  // Again 10 and 13: 276 twelfths = 23 counts exactly (the half count was not lost).
  s = c.step(wheels(20, 26), wheels(10, 10));
  EXPECT_EQ(s.left, 23);
  EXPECT_EQ(s.right, 10);
  EXPECT_EQ(s.flags, 0u);
}

TEST(SideCombiner, EachWheelWrapsOnItsOwn) {
  SideWheelsConfig cfg = two_wheels();
  cfg.counter_bits = 16;
  SideCombiner c = make(cfg);
  // Wheel 0 sits 8 below the 16-bit signed wrap (32767), wheel 1 near zero.
  (void)c.step(wheels(32760, 100), wheels(0, 0));
  // Wheel 0 moves 10 counts: 32770 reads back as 32770 - 65536 = -32766 (sign-extended), so its
  // wrap-aware delta is -32766 - 32760 + 65536 = 10; wheel 1 moves 10 without wrapping. Mean 10.
  const SideStep s = c.step(wheels(-32766, 110), wheels(0, 0));
  EXPECT_EQ(s.left, 10);
  // The same reading given unsigned (32770) is the same counter value.
  const SideStep u = c.step(wheels(32780, 120), wheels(0, 0));
  EXPECT_EQ(u.left, 20);
}

TEST(SideCombiner, FaultedWheelIsDroppedAndReReferenced) {
  SideCombiner d = make(two_wheels());
  (void)d.step(wheels(0, 0), wheels(0, 0));
  EXPECT_EQ(d.step(wheels(10, 10), wheels(0, 0)).left, 10);
  // Wheel 1 faulted (its reading is garbage): the side's travel is wheel 0's 10 alone.
  SideStep s = d.step(wheels(20, 999999, 0b10), wheels(0, 0));
  EXPECT_EQ(s.left, 20);
  EXPECT_EQ(s.flags, static_cast<std::uint32_t>(kEncoderWheelDropped));
  EXPECT_EQ(d.counters().wheel_drops, 1u);
  // Still faulted: still dropped, no new event.
  s = d.step(wheels(30, 12345, 0b10), wheels(0, 0));
  EXPECT_EQ(s.left, 30);
  EXPECT_EQ(d.counters().wheel_drops, 1u);
  // Wheel 1 returns at 500 (it moved while nobody could trust it): 500 is its new reference, the
  // 490 counts are not added; this read counts wheel 0's 10 only.
  s = d.step(wheels(40, 500), wheels(0, 0));
  EXPECT_EQ(s.left, 40);
  EXPECT_EQ(s.flags, 0u);
  // Both again: deltas 10 and 10.
  s = d.step(wheels(50, 510), wheels(0, 0));
  EXPECT_EQ(s.left, 50);
}

// A wheel faulted before it was ever read (a controller not yet heard from) is left out of its
// side and flagged, but it dropped out of nothing: no wheel_drops event until it has counted.
TEST(SideCombiner, AWheelFaultedFromTheStartIsNoDropEvent) {
  SideCombiner d = make(two_wheels());
  SideStep s = d.step(wheels(0, 0, 0b10), wheels(0, 0));
  EXPECT_EQ(s.flags, static_cast<std::uint32_t>(kEncoderWheelDropped));
  s = d.step(wheels(10, 0, 0b10), wheels(0, 0));
  EXPECT_EQ(s.left, 10);  // wheel 0 alone
  EXPECT_EQ(d.counters().wheel_drops, 0u);
  (void)d.step(wheels(20, 300), wheels(0, 0));  // wheel 1 heard: its reference
  (void)d.step(wheels(30, 310, 0b10), wheels(0, 0));
  EXPECT_EQ(d.counters().wheel_drops, 1u);  // now it was counting: an event
}

TEST(SideCombiner, AllWheelsOfASideFaultedIsStale) {
  SideCombiner c = make(two_wheels());
  (void)c.step(wheels(0, 0), wheels(0, 0));
  (void)c.step(wheels(10, 10), wheels(10, 10));
  // Left: both faulted: count kept at 10, stale; right moves on.
  SideStep s = c.step(wheels(77, 88, 0b11), wheels(20, 20));
  EXPECT_EQ(s.left, 10);
  EXPECT_EQ(s.right, 20);
  EXPECT_EQ(s.flags, static_cast<std::uint32_t>(kEncoderStaleLeft));
  EXPECT_EQ(c.counters().stale_events, 1u);
  EXPECT_EQ(c.counters().wheel_drops, 2u);
  s = c.step(wheels(77, 88, 0b11), wheels(30, 30));
  EXPECT_EQ(c.counters().stale_events, 1u);  // one event per stale interval
  // Both back at 100: new references, count still 10 and no flag; then deltas 5 and 5.
  s = c.step(wheels(100, 100), wheels(40, 40));
  EXPECT_EQ(s.left, 10);
  EXPECT_EQ(s.flags, 0u);
  EXPECT_EQ(c.step(wheels(105, 105), wheels(50, 50)).left, 15);
}

TEST(SideCombiner, MedianAndLeastMagnitudeOfThreeWheels) {
  // Deltas 10, 11, 30 (wheel 2 spinning): mean 51 / 3 = 17, median 11, least magnitude 10.
  const SideCombine ways[] = {SideCombine::kMean, SideCombine::kMedian,
                              SideCombine::kLeastMagnitude};
  const std::int64_t expect[] = {17, 11, 10};
  for (int k = 0; k < 3; ++k) {
    SideWheelsConfig cfg = two_wheels();
    cfg.wheels_per_side = 3;
    cfg.combine = ways[k];
    SideCombiner c = make(cfg);
    SideReadings a, b;
    (void)c.step(a, a);
    b.counts = {10, 11, 30, 0};
    EXPECT_EQ(c.step(b, a).left, expect[k]) << choice_name(kSideCombineNames, ways[k]);
  }
  // Four wheels, median: deltas -4, 2, 6, 9 -> (2 + 6) / 2 = 4.
  SideWheelsConfig cfg = two_wheels();
  cfg.wheels_per_side = 4;
  cfg.combine = SideCombine::kMedian;
  SideCombiner c = make(cfg);
  SideReadings a, b;
  (void)c.step(a, a);
  b.counts = {9, -4, 6, 2};
  EXPECT_EQ(c.step(b, a).left, 4);
}

// Slip threshold: window 0.05 s of 0.01 s reads = 5 reads, slip_counts 8, slip_fraction 0.1.
// Wheel 0 moves 100 counts a read, wheel 1 100 + x. After five deltas both are clean for the
// whole window: w0 = 500, w1 = 500 + 5x, spread 5x, mean 500 + 2.5x, threshold
// 8 + 0.1 (500 + 2.5x) = 58 + 0.25x. Slip iff 5x > 58 + 0.25x, i.e. x > 12.21:
//   x = 12: spread 60, threshold 61    -> ratio 0.98361, no flag
//   x = 13: spread 65, threshold 61.25 -> ratio 1.06122, flagged
SideStep drive_with_excess(SideCombiner& c, std::int64_t x, int reads) {
  SideStep s;
  for (int k = 0; k <= reads; ++k)
    s = c.step(wheels(100 * k, (100 + x) * k), wheels(100 * k, 100 * k));
  return s;
}

SideWheelsConfig slip_config() {
  SideWheelsConfig c = two_wheels();
  c.read_period = 0.01;
  c.slip_window = 0.05;
  c.slip_counts = 8;
  c.slip_fraction = 0.1;
  return c;
}

TEST(SideCombiner, SlipBelowTheThresholdIsNotFlagged) {
  SideCombiner c = make(slip_config());
  EXPECT_EQ(c.window_reads(), 5);
  const SideStep s = drive_with_excess(c, 12, 20);
  EXPECT_NEAR(s.ratio_left, 60.0 / 61.0, 1e-12);
  EXPECT_EQ(s.ratio_right, 0.0);  // spread 0 over threshold 58
  EXPECT_EQ(s.flags, 0u);
  EXPECT_EQ(s.spread_left, 0);
  EXPECT_EQ(c.counters().slip_events, 0u);
}

TEST(SideCombiner, SlipAboveTheThresholdIsFlaggedOncePerInterval) {
  SideCombiner c = make(slip_config());
  // Four reads of deltas: wheel 1 not yet clean for a whole window, nothing compared.
  SideStep s = drive_with_excess(c, 13, 4);
  EXPECT_EQ(s.flags, 0u);
  EXPECT_EQ(s.ratio_left, 0.0);
  // The fifth: flagged; the interval's spread starts with the window's 65 counts.
  s = c.step(wheels(500, 565), wheels(500, 500));
  EXPECT_NEAR(s.ratio_left, 65.0 / 61.25, 1e-12);
  EXPECT_EQ(s.flags, static_cast<std::uint32_t>(kEncoderSlipLeft));
  EXPECT_EQ(s.spread_left, 65);
  EXPECT_EQ(s.spread_right, 0);
  EXPECT_EQ(c.counters().slip_events, 1u);
  // Still slipping: this read's spread of deltas, 13; no new event.
  s = c.step(wheels(600, 678), wheels(600, 600));
  EXPECT_EQ(s.spread_left, 13);
  EXPECT_EQ(c.counters().slip_events, 1u);
  // The wheels agree again: the window forgets the excess one read at a time. After five
  // agreeing reads the spread is 0 and the flag is down; a new excess is a second event.
  for (int k = 1; k <= 5; ++k) s = c.step(wheels(600 + 100 * k, 678 + 100 * k), wheels(0, 0));
  EXPECT_EQ(s.flags & kEncoderSlipLeft, 0u);
  EXPECT_EQ(s.spread_left, 0);
  for (int k = 6; k <= 11; ++k)
    s = c.step(wheels(600 + 100 * k, 678 + 100 * 5 + 150 * (k - 5)), wheels(0, 0));
  EXPECT_EQ(c.counters().slip_events, 2u);
}

TEST(SideCombiner, ConfigOutsideItsTableIsRefusedByKey) {
  SideWheelsConfig c = two_wheels();
  c.wheels_per_side = 5;
  auto r = SideCombiner::create(c);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().message, "wheels_per_side = 5 is outside the allowed range [1, 4]");
  c = two_wheels();
  c.read_period = 0.01;
  c.slip_window = 0.005;  // below one read
  r = SideCombiner::create(c);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().message, "slip_window = 0.005 s is outside the allowed range [0.01, 1.28] s");
  c = two_wheels();
  c.slip_counts = 0;  // the threshold must stay positive
  EXPECT_FALSE(SideCombiner::create(c).ok());
}

}  // namespace
}  // namespace odo
