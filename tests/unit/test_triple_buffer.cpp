#include <gtest/gtest.h>

#include <atomic>
#include <thread>

#include "odo/firmware/triple_buffer.hpp"

namespace odo::fw {
namespace {

struct Pair {
  long a = 0;
  long b = 0;  // always -a: a torn read would show a + b != 0
};

TEST(TripleBuffer, EmptyThenNewest) {
  TripleBuffer<Pair> tb;
  Pair p;
  EXPECT_FALSE(tb.latest(p));
  tb.publish({1, -1});
  tb.publish({2, -2});
  ASSERT_TRUE(tb.latest(p));
  EXPECT_EQ(p.a, 2);
  ASSERT_TRUE(tb.latest(p));  // still the newest when nothing new came
  EXPECT_EQ(p.a, 2);
}

TEST(TripleBuffer, NeverTornAndMonotonicAcrossThreads) {
  TripleBuffer<Pair> tb;
  std::atomic<bool> done{false};
  std::thread writer([&] {
    for (long i = 1; i <= 200000; ++i) tb.publish({i, -i});
    done = true;
  });
  long last = 0, reads = 0;
  Pair p;
  while (!done.load() || reads == 0) {
    if (tb.latest(p)) {
      ASSERT_EQ(p.a + p.b, 0);
      ASSERT_GE(p.a, last);
      last = p.a;
      ++reads;
    }
  }
  writer.join();
  ASSERT_TRUE(tb.latest(p));
  EXPECT_EQ(p.a, 200000);
}

}  // namespace
}  // namespace odo::fw
