// ClockMap: a controller clock mapped onto the host's by the lower envelope of the arrival
// offsets, with drift. Numbers derived by hand in the comments.
#include <gtest/gtest.h>

#include <cstdint>

#include "odo/odometry/clock_map.hpp"

namespace odo {
namespace {

constexpr std::int64_t kMs = 1'000'000;  // [ns]

// The scene: the controller stamps a sample every 10 ms (c = k * 10 ms). The host clock reads
// 1e9 ns when the controller's reads 0 and runs 100 ppm fast: the host time of the stamp is
// 1e9 + c + c / 10^4 = 1e9 + c + 1000 k [ns]. Every sample arrives 1 ms after its stamp, and
// those with k % 3 == 1 5 ms later still (transport spikes).
std::int64_t host_of_stamp(int k) {
  return 1'000'000'000 + k * 10 * kMs + 1000 * k;
}
std::int64_t arrival(int k) {
  return host_of_stamp(k) + 1 * kMs + (k % 3 == 1 ? 5 * kMs : 0);
}

TEST(ClockMap, FollowsDriftIgnoresSpikes) {
  ClockMap m(100 * kMs, 4);
  for (int k = 0; k <= 400; ++k) {
    const TimeNs t = m.map(k * 10 * kMs, arrival(k));
    // Windows of 100 ms: [k 0..9], [10..19], ... Each window's minimum offset is its first
    // sample without a spike (the offset grows 1000 ns per sample): k = 0 (offset 1e9 + 1 ms),
    // k = 11 (1e9 + 1 ms + 11000 ns), k = 20, k = 31 (k = 30 has 30 % 3 == 0: k = 30), ...
    // From the second closed window on (k >= 20) the drift is the slope between two points of
    // the line: 11000 ns / 110 ms = 1e-4 exactly, and every sample, spiked or not, maps to the
    // line: its stamp's host time plus the 1 ms minimum delay.
    if (k >= 20) {
      ASSERT_EQ(t, host_of_stamp(k) + 1 * kMs) << k;
    } else {
      // Before that the drift is 0 and the base is k = 0's minimum: the error is the drift
      // since k = 0, -1000 ns per sample: at most 19 * 1000 ns = 19 us early.
      EXPECT_LE(t, host_of_stamp(k) + 1 * kMs) << k;
      EXPECT_GE(t, host_of_stamp(k) + 1 * kMs - 19'000) << k;
    }
  }
  EXPECT_NEAR(m.drift(), 1e-4, 1e-12);
}

TEST(ClockMap, FasterSampleLowersTheEnvelopeAtOnce) {
  ClockMap m(100 * kMs, 4);
  for (int k = 0; k < 50; ++k) m.map(k * 10 * kMs, arrival(k));
  // k = 50 arrives after 0.4 ms instead of 1 ms: it is proof the offset is lower; it maps to its
  // own arrival (never later than it arrived).
  const std::int64_t fast = host_of_stamp(50) + 400'000;
  EXPECT_EQ(m.map(50 * 10 * kMs, fast), fast);
}

TEST(ClockMap, DriftChangeIsFollowed) {
  // Same scene to k = 100, then the host clock runs 50 ppm slow of the controller's instead:
  // host(k) = host_of_stamp(100) + (k - 100) * (10 ms - 500 ns). Arrivals 1 ms later, no spikes.
  ClockMap m(100 * kMs, 4);
  auto host2 = [](int k) { return host_of_stamp(100) + (k - 100) * (10 * kMs - 500); };
  for (int k = 0; k <= 100; ++k) m.map(k * 10 * kMs, host_of_stamp(k) + kMs);
  for (int k = 101; k <= 200; ++k) {
    const TimeNs t = m.map(k * 10 * kMs, host2(k) + kMs);
    // Once the ring (4 windows = 40 samples) holds only minima after the change (k = 110, 120,
    // 130, 140 are the window starts and minima: offsets fall), the line is exact again.
    if (k >= 150) {
      ASSERT_EQ(t, host2(k) + kMs) << k;
    }
    // In between the estimate is never later than the arrival.
    EXPECT_LE(t, host2(k) + kMs);
  }
  EXPECT_NEAR(m.drift(), -5e-5, 1e-12);
}

TEST(ClockMap, ResetStartsOver) {
  ClockMap m(100 * kMs, 4);
  for (int k = 0; k < 50; ++k) m.map(k * 10 * kMs, arrival(k));
  m.reset();
  EXPECT_EQ(m.drift(), 0.0);
  // The controller rebooted: its clock restarts at 0, arriving at host 5 s + 1 ms: maps there.
  EXPECT_EQ(m.map(0, 5'000'000'000 + kMs), 5'000'000'000 + kMs);
}

}  // namespace
}  // namespace odo
