#include <gtest/gtest.h>

#include <cstdint>
#include <thread>

#include "odo/loop/spsc_ring.hpp"

namespace odo::loop {
namespace {

TEST(SpscRing, CapacityRoundsUpToAPowerOfTwoOfAtLeastTwo) {
  EXPECT_EQ(SpscRing<int>(0).capacity(), 2u);
  EXPECT_EQ(SpscRing<int>(2).capacity(), 2u);
  EXPECT_EQ(SpscRing<int>(5).capacity(), 8u);
  EXPECT_EQ(SpscRing<int>(8).capacity(), 8u);
}

TEST(SpscRing, FirstInFirstOutAndAFullRingDropsTheNewValue) {
  SpscRing<int> r(4);
  int v = 0;
  EXPECT_FALSE(r.pop(v));
  for (int i = 1; i <= 4; ++i) EXPECT_TRUE(r.push(i));
  EXPECT_FALSE(r.push(5));  // full: 5 is dropped, 1..4 kept
  EXPECT_EQ(r.dropped(), 1u);
  for (int i = 1; i <= 4; ++i) {
    ASSERT_TRUE(r.pop(v));
    EXPECT_EQ(v, i);
  }
  EXPECT_FALSE(r.pop(v));
  EXPECT_TRUE(r.push(6));  // room again after the pops
  ASSERT_TRUE(r.pop(v));
  EXPECT_EQ(v, 6);
}

TEST(SpscRing, SlotsWrapAroundManyTimesInOrder) {
  // Three values in flight in a ring of four: the running indices pass every slot 750 times.
  SpscRing<int> r(4);
  int next_in = 0, next_out = 0, v = -1;
  for (; next_in < 3; ++next_in) ASSERT_TRUE(r.push(next_in));
  for (int k = 0; k < 3000; ++k) {
    ASSERT_TRUE(r.pop(v));
    EXPECT_EQ(v, next_out++);
    ASSERT_TRUE(r.push(next_in++));
  }
  EXPECT_EQ(r.dropped(), 0u);
}

TEST(SpscRing, ProducerAndConsumerThreadsLoseAndReorderNothing) {
  // push_wait on a small ring: the producer outruns the consumer and must wait, never drop.
  // Under ThreadSanitizer this also checks the acquire/release pairs of push and pop.
  constexpr std::uint64_t kValues = 200000;
  SpscRing<std::uint64_t> r(16);
  std::thread producer([&r] {
    for (std::uint64_t i = 0; i < kValues; ++i) r.push_wait(i, [] { std::this_thread::yield(); });
  });
  std::uint64_t expected = 0, v = 0, out_of_order = 0;
  while (expected < kValues) {
    if (!r.pop(v)) {
      std::this_thread::yield();
      continue;
    }
    if (v != expected) ++out_of_order;
    expected = v + 1;
  }
  producer.join();
  EXPECT_EQ(out_of_order, 0u);
  EXPECT_EQ(r.dropped(), 0u);
  EXPECT_FALSE(r.pop(v));
}

}  // namespace
}  // namespace odo::loop
