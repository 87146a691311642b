#include <gtest/gtest.h>

#include "odo/loop/latency_histogram.hpp"

namespace odo::fw {
namespace {

TEST(LatencyHistogram, BucketsAreExactBelow64AndLogLinearAbove) {
  // Values 0..63 have a bucket each (block 0 holds 0..31, block 1 holds 32..63 in steps of 1).
  for (TimeNs v = 0; v < 64; ++v) {
    EXPECT_EQ(loop::LatencyHistogram::index(v), static_cast<std::size_t>(v));
    EXPECT_EQ(loop::LatencyHistogram::upper_bound(loop::LatencyHistogram::index(v)), v);
  }
  // 64..127: e = 6, buckets of 2 ns: 64 and 65 share bucket 2*32 + 0 = 64, 66 is bucket 65.
  EXPECT_EQ(loop::LatencyHistogram::index(64), 64u);
  EXPECT_EQ(loop::LatencyHistogram::index(65), 64u);
  EXPECT_EQ(loop::LatencyHistogram::index(66), 65u);
  EXPECT_EQ(loop::LatencyHistogram::upper_bound(64), 65);
  // 1000 ns: e = 9, buckets of 2^4 = 16 ns; 1000 >> 4 = 62, sub-bucket 62 - 32 = 30, index
  // (9 - 5 + 1) * 32 + 30 = 190, covering [62 * 16, 63 * 16 - 1] = [992, 1007].
  EXPECT_EQ(loop::LatencyHistogram::index(1000), 190u);
  EXPECT_EQ(loop::LatencyHistogram::upper_bound(190), 1007);
  EXPECT_EQ(loop::LatencyHistogram::index(992), 190u);
  EXPECT_EQ(loop::LatencyHistogram::index(991), 189u);
}

TEST(LatencyHistogram, UpperBoundIsWithinOneThirtySecondOfTheValue) {
  // Every value up to 2^40 ns maps to a bucket whose upper bound is >= v and <= v * (1 + 1/32).
  for (TimeNs v = 1; v < (TimeNs{1} << 40); v = v * 3 / 2 + 7) {
    const TimeNs ub = loop::LatencyHistogram::upper_bound(loop::LatencyHistogram::index(v));
    EXPECT_GE(ub, v);
    EXPECT_LE(ub, v + v / 32) << v;
  }
  // Beyond the range: the last bucket, not an out-of-range index.
  EXPECT_EQ(loop::LatencyHistogram::index(TimeNs{1} << 50), loop::LatencyHistogram::kBuckets - 1);
}

TEST(LatencyHistogram, SummaryOfOneToThousand) {
  // Values 1..1000 ns once each: mean 500500 / 1000 = 500 (integer ns). p99 is the 990th value,
  // 990 ns, in bucket [976, 991] (e = 9, 990 >> 4 = 61): reported as 991. p99.9 is the 999th
  // value, in bucket [992, 1007]: 1007, clamped to the maximum 1000.
  loop::LatencyHistogram h;
  for (TimeNs v = 1000; v >= 1; --v) h.record(v);
  const loop::TimingSummary s = h.summary();
  EXPECT_EQ(s.count, 1000u);
  EXPECT_EQ(s.min, 1);
  EXPECT_EQ(s.max, 1000);
  EXPECT_EQ(s.mean, 500);
  EXPECT_EQ(s.p99, 991);
  EXPECT_EQ(s.p999, 1000);
  // Median: the 500th value, 500 ns, e = 8, buckets of 8 ns: 500 >> 3 = 62, bucket [496, 503].
  EXPECT_EQ(h.percentile(0.5), 503);
}

TEST(LatencyHistogram, RareOutliersShowInMaxButNotInP99) {
  // 10000 values of 20 us and 5 of 2 ms: 5 / 10005 = 0.05 % lie above p99 and above p99.9
  // (rank ceil(0.999 * 10005) = 9995 <= 10000), so both percentiles stay at 20 us's bucket.
  loop::LatencyHistogram h;
  for (int i = 0; i < 10000; ++i) h.record(20'000);
  for (int i = 0; i < 5; ++i) h.record(2'000'000);
  const loop::TimingSummary s = h.summary();
  // 20000 ns: e = 14, buckets of 2^9 = 512 ns: 20000 >> 9 = 39, bucket [19968, 20479].
  EXPECT_EQ(s.p99, 20479);
  EXPECT_EQ(s.p999, 20479);
  EXPECT_EQ(s.max, 2'000'000);
  EXPECT_EQ(s.min, 20'000);
  // Mean: (10000 * 20000 + 5 * 2e6) / 10005 = 2.1e8 / 10005 = 20989.5 -> 20989 ns.
  EXPECT_EQ(s.mean, 20989);
}

TEST(LatencyHistogram, NegativeCountsAsZeroAndResetForgets) {
  loop::LatencyHistogram h;
  h.record(-5);
  EXPECT_EQ(h.summary().min, 0);
  EXPECT_EQ(h.summary().max, 0);
  h.reset();
  EXPECT_EQ(h.count(), 0u);
  const loop::TimingSummary s = h.summary();
  EXPECT_EQ(s.max, 0);
  EXPECT_EQ(s.p99, 0);
}

}  // namespace
}  // namespace odo::fw
