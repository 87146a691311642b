// The 4x quadrature table and the event tracker of the GPIO backend.
#include <gtest/gtest.h>

#include "odo/drivers/gpio_quadrature.hpp"

#include "odo/drivers/quad_tracker.hpp"
#include "odo/hal/quadrature.hpp"

namespace odo {
namespace {

// States packed (A << 1) | B. Forward (A leads B) is the Gray sequence 00 -> 10 -> 11 -> 01,
// i.e. 0 -> 2 -> 3 -> 1 -> 0; backward is the reverse. Every one of the 16 (from, to) pairs is
// listed: 4 no-change, 4 forward, 4 backward, 4 illegal (both channels flipped: 0<->3, 1<->2).
TEST(QuadTable, EveryTransition) {
  struct Case {
    QuadState from, to;
    QuadStep want;
  };
  const Case cases[16] = {
      {0, 0, QuadStep::kNone},     {1, 1, QuadStep::kNone},     {2, 2, QuadStep::kNone},
      {3, 3, QuadStep::kNone},     {0, 2, QuadStep::kForward},  {2, 3, QuadStep::kForward},
      {3, 1, QuadStep::kForward},  {1, 0, QuadStep::kForward},  {2, 0, QuadStep::kBackward},
      {3, 2, QuadStep::kBackward}, {1, 3, QuadStep::kBackward}, {0, 1, QuadStep::kBackward},
      {0, 3, QuadStep::kInvalid},  {3, 0, QuadStep::kInvalid},  {1, 2, QuadStep::kInvalid},
      {2, 1, QuadStep::kInvalid},
  };
  int seen[4][4] = {};
  for (const Case& c : cases) {
    EXPECT_EQ(quad_decode(c.from, c.to), c.want) << int(c.from) << "->" << int(c.to);
    ++seen[c.from][c.to];
  }
  for (auto& row : seen)
    for (int n : row) EXPECT_EQ(n, 1);  // the list above is complete and has no duplicates
  EXPECT_EQ(quad_delta(QuadStep::kForward), 1);
  EXPECT_EQ(quad_delta(QuadStep::kBackward), -1);
  EXPECT_EQ(quad_delta(QuadStep::kNone), 0);
  EXPECT_EQ(quad_delta(QuadStep::kInvalid), 0);
}

TEST(QuadTable, IdealEncoderPositions) {
  // quad_state_at walks the forward sequence: count k -> k+1 is always one forward step, also
  // across zero and for negative counts.
  for (std::int64_t k = -9; k < 9; ++k) {
    EXPECT_EQ(quad_decode(quad_state_at(k), quad_state_at(k + 1)), QuadStep::kForward) << k;
    EXPECT_EQ(quad_decode(quad_state_at(k + 1), quad_state_at(k)), QuadStep::kBackward) << k;
  }
  EXPECT_EQ(quad_state_at(0), quad_state(false, false));
  EXPECT_EQ(quad_state_at(1), quad_state(true, false));
  EXPECT_EQ(quad_state_at(-1), quad_state(false, true));
}

using drivers::QuadTracker;
constexpr std::uint8_t kA = QuadTracker::kLineA;
constexpr std::uint8_t kB = QuadTracker::kLineB;

TEST(QuadTracker, ForwardAndBackCycles) {
  QuadTracker t;
  t.reset(0);
  // Forward: A rises, B rises, A falls, B falls = 4 counts (one encoder line).
  for (int cycle = 0; cycle < 3; ++cycle) {
    EXPECT_EQ(t.apply(kA, kA), QuadStep::kForward);
    EXPECT_EQ(t.apply(kB, kB), QuadStep::kForward);
    EXPECT_EQ(t.apply(kA, 0), QuadStep::kForward);
    EXPECT_EQ(t.apply(kB, 0), QuadStep::kForward);
  }
  EXPECT_EQ(t.count(), 12);
  // Backward: B rises first.
  EXPECT_EQ(t.apply(kB, kB), QuadStep::kBackward);
  EXPECT_EQ(t.apply(kA, kA), QuadStep::kBackward);
  EXPECT_EQ(t.count(), 10);
  EXPECT_EQ(t.invalid(), 0u);
}

TEST(QuadTracker, BothLinesAtOnceIsInvalidNotMotion) {
  QuadTracker t;
  t.reset(0);
  EXPECT_EQ(t.apply(kA | kB, kA | kB), QuadStep::kInvalid);  // 00 -> 11
  EXPECT_EQ(t.count(), 0);
  EXPECT_EQ(t.invalid(), 1u);
  EXPECT_EQ(t.state(), 3);                        // the new levels are adopted
  EXPECT_EQ(t.apply(kA, 0), QuadStep::kForward);  // 11 -> 01 is forward from there
  EXPECT_EQ(t.count(), 1);
}

TEST(QuadTracker, BurstOfInvalidTransitionsCountsEachAndMovesNothing) {
  // Fault matrix row "invalid quadrature transition burst": 1000 illegal transitions in a row
  // (both lines at once, and repeated edges of one line), starting from every state.
  constexpr std::uint8_t kFwd[4] = {2, 0, 3, 1};  // next state forward: 0->2->3->1->0
  QuadTracker t;
  t.reset(0);
  for (int i = 0; i < 7; ++i) {  // some motion first: 7 forward steps
    const QuadState s = t.state();
    ASSERT_EQ(t.apply(static_cast<std::uint8_t>(s ^ kFwd[s]), kFwd[s]), QuadStep::kForward);
  }
  const std::int64_t count = t.count();
  constexpr int kBurst = 1000;
  for (int i = 0; i < kBurst; ++i) {
    const QuadState s = t.state();
    if (i % 3 == 2) {  // an edge of A to the level A already has: its opposite edge was lost
      EXPECT_EQ(t.apply(kA, s), QuadStep::kInvalid) << i;
      EXPECT_EQ(t.state(), s);
    } else {  // both lines flip at once
      EXPECT_EQ(t.apply(kA | kB, static_cast<std::uint8_t>(s ^ 3u)), QuadStep::kInvalid) << i;
      EXPECT_EQ(t.state(), s ^ 3u);  // the new levels are adopted
    }
  }
  EXPECT_EQ(t.count(), count);  // no motion from the burst
  EXPECT_EQ(t.invalid(), static_cast<std::uint64_t>(kBurst));
  // Legal steps after the burst count exactly again.
  for (int i = 0; i < 100; ++i) {
    const QuadState s = t.state();
    ASSERT_EQ(t.apply(static_cast<std::uint8_t>(s ^ kFwd[s]), kFwd[s]), QuadStep::kForward);
  }
  EXPECT_EQ(t.count(), count + 100);
  EXPECT_EQ(t.invalid(), static_cast<std::uint64_t>(kBurst));
}

TEST(QuadTracker, RepeatedEdgeMeansALostEvent) {
  QuadTracker t;
  t.reset(0);
  EXPECT_EQ(t.apply(kA, kA), QuadStep::kForward);
  // A rises again: its falling edge in between was lost.
  EXPECT_EQ(t.apply(kA, kA), QuadStep::kInvalid);
  EXPECT_EQ(t.count(), 1);
  EXPECT_EQ(t.invalid(), 1u);
}

TEST(QuadTracker, ResyncCountsADifferenceOnly) {
  QuadTracker t;
  t.reset(2);
  EXPECT_FALSE(t.resync(2));
  EXPECT_EQ(t.invalid(), 0u);
  EXPECT_TRUE(t.resync(1));
  EXPECT_EQ(t.invalid(), 1u);
  EXPECT_EQ(t.count(), 0);
  EXPECT_EQ(t.state(), 1);
}

TEST(QuadTracker, LateEdgeIsAdoptedAsInvalid) {
  QuadTracker t;
  t.reset(0);
  EXPECT_EQ(t.apply(kB, kB), QuadStep::kBackward);  // 00 -> 01
  t.adopt(kA, kA);                                  // a late A edge: 01 -> 11 without motion
  EXPECT_EQ(t.count(), -1);
  EXPECT_EQ(t.invalid(), 1u);
  EXPECT_EQ(t.state(), 3);
}

}  // namespace
// The GPIO decoder's pending buffer: a batch of events larger than the free room keeps what
// fits and reports the rest as dropped (counted in GpioWheelStats::dropped, never lost silently).
TEST(GpioBatch, EventsBeyondTheFreeRoomAreCountedAsDropped) {
  // 64 events into 100 free slots: all taken. 64 into 10: 10 taken, 54 dropped. Into 0: 64 dropped.
  EXPECT_EQ(drivers::split_batch(64, 100).taken, 64u);
  EXPECT_EQ(drivers::split_batch(64, 100).dropped, 0u);
  EXPECT_EQ(drivers::split_batch(64, 10).taken, 10u);
  EXPECT_EQ(drivers::split_batch(64, 10).dropped, 54u);
  EXPECT_EQ(drivers::split_batch(64, 0).taken, 0u);
  EXPECT_EQ(drivers::split_batch(64, 0).dropped, 64u);
}

}  // namespace odo
