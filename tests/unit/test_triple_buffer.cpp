#include <gtest/gtest.h>

#include <atomic>
#include <thread>

#include "odo/loop/triple_buffer.hpp"

namespace odo::fw {
namespace {

struct Pair {
  long a = 0;
  long b = 0;  // always -a: a torn read would show a + b != 0
};

TEST(TripleBuffer, EmptyThenNewest) {
  loop::TripleBuffer<Pair> tb;
  Pair p;
  EXPECT_FALSE(tb.latest(p));
  tb.publish({1, -1});
  tb.publish({2, -2});
  ASSERT_TRUE(tb.latest(p));
  EXPECT_EQ(p.a, 2);
  ASSERT_TRUE(tb.latest(p));  // still the newest when nothing new came
  EXPECT_EQ(p.a, 2);
}

constexpr long kWrites = 200000;

// read_while_writing: runs write(i) for i = 1..kWrites on a writer thread while this thread
// reads; every value read must be untorn and no older than the one before, the last one the
// newest.
template <class Write>
void read_while_writing(loop::TripleBuffer<Pair>& tb, Write write) {
  std::atomic<bool> done{false};
  std::thread writer([&] {
    for (long i = 1; i <= kWrites; ++i) write(i);
    done = true;
  });
  long last = 0, reads = 0, bad = 0;
  Pair p;
  while (!done.load() || reads == 0) {
    if (tb.latest(p)) {
      // Counted, not asserted here: a failed ASSERT would return with the writer not joined.
      if (p.a + p.b != 0 || p.a < last) ++bad;
      last = p.a;
      ++reads;
    }
  }
  writer.join();
  EXPECT_EQ(bad, 0) << "torn or older values among " << reads << " reads";
  ASSERT_TRUE(tb.latest(p));
  EXPECT_EQ(p.a, kWrites);
}

TEST(TripleBuffer, NeverTornAndMonotonicAcrossThreads) {
  loop::TripleBuffer<Pair> tb;
  read_while_writing(tb, [&](long i) { tb.publish({i, -i}); });
}

TEST(TripleBuffer, InPlaceBackThenPublishAndNewest) {
  loop::TripleBuffer<Pair> tb;
  EXPECT_EQ(tb.newest().a, 0);  // T{} before the first publish
  for (long i = 1; i <= 10; ++i) {
    Pair& b = tb.back();
    EXPECT_NE(&b, &tb.newest());  // the writer never fills the value it last published
    b.a = i;
    b.b = -i;
    tb.publish();
    EXPECT_EQ(tb.newest().a, i);
    EXPECT_EQ(tb.newest().b, -i);
  }
  Pair p;
  ASSERT_TRUE(tb.latest(p));
  EXPECT_EQ(p.a, 10);
  // Once the reader holds the newest value, the writer still reads it (and never writes it).
  EXPECT_NE(&tb.back(), &tb.newest());
  EXPECT_EQ(tb.newest().a, 10);
}

TEST(TripleBuffer, InPlaceWriterNeverTearsWhatTheReaderCopies) {
  // The loop's way: fill the back buffer field by field, publish, read the newest back while the
  // reader copies (ThreadSanitizer checks that no buffer is written by one side while the other
  // reads it).
  loop::TripleBuffer<Pair> tb;
  long newest_mismatch = 0;
  read_while_writing(tb, [&](long i) {
    Pair& b = tb.back();
    b.a = i;
    b.b = -i;
    tb.publish();
    if (tb.newest().a != i || tb.newest().b != -i) ++newest_mismatch;
  });
  EXPECT_EQ(newest_mismatch, 0);
}

}  // namespace
}  // namespace odo::fw
