// The HCTL-1100 driver against the register model, through the same ParallelBus interface the
// libgpiod bus implements: wrap-around at full speed both ways, torn reads, every fault path,
// and the firmware loop on top.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>

#include "odo/drivers/hctl1100_encoder.hpp"
#include "odo/loop/loop.hpp"
#include "odo/odometry/count_delta.hpp"
#include "odo/sim/hctl1100_model.hpp"
#include "odo/sim/virtual_clock.hpp"

namespace odo {
namespace {

using drivers::Hctl1100Config;
using drivers::Hctl1100Encoder;
using sim::Hctl1100Model;
using sim::SimHctlBus;

// Two wheels turning at constant count rates; every bus cycle takes `cycle_ns` of virtual time,
// so the counters move while a multi-byte reading is in progress.
struct World final : sim::BusCycleHook {
  World(Hctl1100Model::Latch latch, double rate_l, double rate_r, TimeNs cycle_ns)
      : left(latch), right(latch), bus(&left, &right), rate{rate_l, rate_r}, cycle(cycle_ns) {
    bus.set_hook(this);
  }
  void on_bus_cycle() noexcept override { advance(cycle); }
  void advance(TimeNs dt) {
    t += dt;
    track(0, left);
    track(1, right);
  }
  // track: the chip counts the disc's motion, except while its wire is cut: then it sees no
  // edges, its counter holds and the motion meanwhile is lost for good.
  void track(int i, Hctl1100Model& m) {
    if (cut[i]) {
      lost[i] = true_counts(i) - seen[i];
      return;
    }
    seen[i] = true_counts(i) - lost[i];
    m.follow(seen[i]);
  }
  // true_counts: where the disc of wheel i is at the current time [counts].
  std::int64_t true_counts(int i) const {
    return static_cast<std::int64_t>(std::floor(rate[i] * to_seconds(t)));
  }
  Hctl1100Model left, right;
  SimHctlBus bus;
  double rate[2];
  TimeNs cycle;
  TimeNs t = 0;
  bool cut[2] = {false, false};   // encoder wire of wheel i cut
  std::int64_t seen[2] = {0, 0};  // counts the chip has seen
  std::int64_t lost[2] = {0, 0};  // counts the disc moved while the wire was cut
};

Hctl1100Config config_for(double max_rate) {
  Hctl1100Config c;
  c.max_counts_per_s = max_rate;
  return c;
}

TEST(Hctl1100Model, FourXDecodingAndSignExtension) {
  Hctl1100Model m;
  m.follow(5);  // five quadrature states forward
  EXPECT_EQ(m.position(), 5);
  m.follow(-3);
  EXPECT_EQ(m.position(), -3);
  // -3 in 24-bit two's complement is 0xFFFFFD: R12H = 0xFF, R13H = 0xFF, R14H = 0xFD.
  EXPECT_EQ(m.read_register(Hctl1100Model::kRegPosMsb), 0xFF);
  EXPECT_EQ(m.read_register(Hctl1100Model::kRegPosMid), 0xFF);
  EXPECT_EQ(m.read_register(Hctl1100Model::kRegPosLsb), 0xFD);
  m.preset(0x7FFFFF);                 // +8388607, the largest value
  m.follow(-2);                       // one more count forward from -3
  EXPECT_EQ(m.position(), -8388608);  // wrapped to the most negative value
  // An illegal transition (both channels flip) is not counted.
  const std::int32_t before = m.position();
  m.sample(static_cast<QuadState>(quad_state_at(m.disc_position()) ^ 3u));
  EXPECT_EQ(m.position(), before);
  EXPECT_EQ(m.illegal_transitions(), 1u);
}

TEST(Hctl1100Model, LsbReadLatchesUpperBytes) {
  Hctl1100Model m(Hctl1100Model::Latch::kLsbLatch);
  m.preset(0x0001FF);
  EXPECT_EQ(m.read_register(Hctl1100Model::kRegPosLsb), 0xFF);
  m.follow(1);  // counter -> 0x000200 after the LSB was read
  EXPECT_EQ(m.read_register(Hctl1100Model::kRegPosMid), 0x01);  // latched, not 0x02
  EXPECT_EQ(m.read_register(Hctl1100Model::kRegPosMsb), 0x00);
  // The MSB read released the latch: the next LSB-first reading is current.
  EXPECT_EQ(m.read_register(Hctl1100Model::kRegPosLsb), 0x00);
  EXPECT_EQ(m.read_register(Hctl1100Model::kRegPosMid), 0x02);
}

// A naive MSB-first single reading of an unlatched chip tears; the driver's never does.
TEST(Hctl1100Driver, ReadingsNeverTearOnAnUnlatchedChip) {
  // 1e6 counts/s, 2 us per bus cycle: the LSB rolls over every 128 us.
  World w(Hctl1100Model::Latch::kNone, 1e6, -1e6, 2'000);
  auto enc = Hctl1100Encoder::create(w.bus, config_for(1.2e6));
  ASSERT_TRUE(enc.ok()) << enc.error().message;
  int naive_torn = 0;
  std::uint32_t lcg = 12345;  // de-phases the readings from the LSB roll-over (reproducibly)
  for (int i = 0; i < 2000; ++i) {
    const std::int64_t before = w.true_counts(0);
    const auto hi = w.bus.read_register(0, Hctl1100Model::kRegPosMsb).value;
    const auto mid = w.bus.read_register(0, Hctl1100Model::kRegPosMid).value;
    const auto lo = w.bus.read_register(0, Hctl1100Model::kRegPosLsb).value;
    const std::int64_t naive = (std::int64_t{hi} << 16) | (mid << 8) | lo;
    if (std::llabs(wrap_delta(before, naive, 24)) > 64) ++naive_torn;

    std::int32_t pos = 0;
    const std::int64_t t0 = w.true_counts(0);
    ASSERT_TRUE(enc->read_position(0, pos));
    const std::int64_t t1 = w.true_counts(0);
    // The accepted reading lies between the true positions at the start and end of the read.
    EXPECT_GE(wrap_delta(t0, pos, 24), 0) << i;
    EXPECT_LE(wrap_delta(t0, pos, 24), t1 - t0) << i;
    lcg = lcg * 1664525u + 1013904223u;
    w.advance(1'000 + (lcg >> 8) % 200'000);
  }
  EXPECT_GT(naive_torn, 0) << "the model should make an unprotected reading tear";
}

// 24-bit wrap at full speed, forward and backward, latched and unlatched chip: the sum of the
// wrap-aware deltas of the driver's readings equals the true travel (to within the motion
// inside the last reading), and nothing is flagged.
void wrap_at_full_speed(Hctl1100Model::Latch latch, double rate) {
  World w(latch, rate, -rate, 1'000);
  // Start 0.05 s of travel before the wrap: +8388607 -> -8388608 forward on the left wheel,
  // -8388608 -> +8388607 backward on the right.
  const auto lead = static_cast<std::int32_t>(std::abs(rate) * 0.05);
  w.left.preset(rate > 0 ? 8388607 - lead : -8388608 + lead);
  w.right.preset(rate > 0 ? -8388608 + lead : 8388607 - lead);
  auto enc = Hctl1100Encoder::create(w.bus, config_for(std::abs(rate) * 1.1));
  ASSERT_TRUE(enc.ok());
  EncoderSample prev = enc->read(w.t);
  ASSERT_EQ(prev.flags, 0u);
  const std::int64_t start_l = w.true_counts(0);
  const std::int64_t start_r = w.true_counts(1);
  std::int64_t sum_l = 0, sum_r = 0;
  bool crossed_l = false;
  for (int tick = 0; tick < 20; ++tick) {  // 0.2 s at 100 Hz
    w.advance(10'000'000);
    const EncoderSample s = enc->read(w.t);
    ASSERT_EQ(s.flags, 0u) << "tick " << tick;
    if ((prev.left > 0) != (s.left > 0) && std::llabs(prev.left) > 4'000'000) crossed_l = true;
    sum_l += wrap_delta(prev.left, s.left, 24);
    sum_r += wrap_delta(prev.right, s.right, 24);
    prev = s;
  }
  EXPECT_TRUE(crossed_l) << "the reading did not cross the 24-bit wrap";
  EXPECT_NEAR(static_cast<double>(sum_l), static_cast<double>(w.true_counts(0) - start_l), 16.0);
  EXPECT_NEAR(static_cast<double>(sum_r), static_cast<double>(w.true_counts(1) - start_r), 16.0);
  EXPECT_GT(std::llabs(sum_l), static_cast<std::int64_t>(std::abs(rate) * 0.15));
}

// Full speed: the LabMate's 0.15 m wheel at 3 m/s with 2048 x 16 counts per wheel turn is
// 3 / (pi * 0.15) * 32768 = 208 600 counts/s; use 250 000.
TEST(Hctl1100Driver, WrapForwardAtFullSpeedUnlatched) {
  wrap_at_full_speed(Hctl1100Model::Latch::kNone, 250'000);
}
TEST(Hctl1100Driver, WrapBackwardAtFullSpeedUnlatched) {
  wrap_at_full_speed(Hctl1100Model::Latch::kNone, -250'000);
}
TEST(Hctl1100Driver, WrapForwardAtFullSpeedLatched) {
  wrap_at_full_speed(Hctl1100Model::Latch::kLsbLatch, 250'000);
}
TEST(Hctl1100Driver, WrapBackwardAtFullSpeedLatched) {
  wrap_at_full_speed(Hctl1100Model::Latch::kLsbLatch, -250'000);
}

TEST(Hctl1100Driver, ImplausibleJumpIsReportedNotIntegrated) {
  World w(Hctl1100Model::Latch::kNone, 1000, 1000, 1'000);
  auto enc = Hctl1100Encoder::create(w.bus, config_for(2000));
  ASSERT_TRUE(enc.ok());
  EncoderSample a = enc->read(w.t);
  w.advance(10'000'000);  // 10 ms: 10 counts, well inside 2000 counts/s * 0.01 s = 20 (+17)
  EncoderSample b = enc->read(w.t);
  EXPECT_EQ(b.flags, 0u);
  EXPECT_EQ(wrap_delta(a.left, b.left, 24), 10);
  // A noise burst adds 5000 counts to the left chip.
  w.left.inject_jump(5000);
  w.advance(10'000'000);
  EncoderSample c = enc->read(w.t);
  EXPECT_TRUE(c.flags & kEncoderImplausibleJump);
  EXPECT_EQ(c.counters.implausible_jumps, 1u);
  EXPECT_EQ(wrap_delta(b.left, c.left, 24), 0) << "the jump must not reach the loop";
  EXPECT_EQ(wrap_delta(b.right, c.right, 24), 10) << "the other wheel is unaffected";
  // From there on the wheel is followed normally again.
  w.advance(10'000'000);
  EncoderSample d = enc->read(w.t);
  EXPECT_EQ(d.flags, 0u);
  EXPECT_EQ(wrap_delta(c.left, d.left, 24), 10);
  EXPECT_EQ(d.counters.implausible_jumps, 1u);
}

TEST(Hctl1100Driver, CutEncoderWireReadsAsAStandingWheelAndIsNotFlagged) {
  // Fault matrix row "encoder wire cut": the chip sees no more edges, so its counter holds:
  // exactly what a standing wheel looks like. The driver has no stale timeout (only the CAN
  // backend has one): no flag, no counter, and the motion during the cut is lost.
  World w(Hctl1100Model::Latch::kNone, 1000, 1000, 1'000);
  auto enc = Hctl1100Encoder::create(w.bus, config_for(2000));
  ASSERT_TRUE(enc.ok());
  const EncoderSample first = enc->read(w.t);
  EncoderSample prev = first;
  auto next = [&] {
    w.advance(10'000'000);  // 10 ms: 10 counts at 1000 counts/s
    const EncoderSample s = enc->read(w.t);
    EXPECT_EQ(s.flags, 0u);
    EXPECT_NEAR(static_cast<double>(wrap_delta(prev.right, s.right, 24)), 10.0, 1.0);
    return s;
  };
  for (int i = 0; i < 50; ++i) prev = next();
  w.cut[0] = true;
  const std::int64_t held = prev.left;
  for (int i = 0; i < 100; ++i) {  // 1 s with the left wire cut
    prev = next();
    EXPECT_EQ(prev.left, held) << "read " << i;
  }
  EXPECT_GE(w.lost[0], 990);  // the disc turned on
  w.cut[0] = false;           // reconnected: counting resumes from the held value
  for (int i = 0; i < 50; ++i) {
    const std::int64_t before = prev.left;
    prev = next();
    EXPECT_NEAR(static_cast<double>(wrap_delta(before, prev.left, 24)), 10.0, 1.0);
  }
  EXPECT_EQ(prev.counters.implausible_jumps, 0u);
  EXPECT_EQ(prev.counters.read_errors, 0u);
  EXPECT_EQ(prev.counters.stale_events, 0u);
  // Left is behind right by the motion during the cut (within one count: the chips are read
  // a few bus cycles apart).
  const auto behind =
      wrap_delta(first.right, prev.right, 24) - wrap_delta(first.left, prev.left, 24);
  EXPECT_NEAR(static_cast<double>(behind), static_cast<double>(w.lost[0]), 1.0);
}

TEST(Hctl1100Driver, BusFaultIsAReadErrorAndLosesNothing) {
  World w(Hctl1100Model::Latch::kNone, 1000, -1000, 1'000);
  auto enc = Hctl1100Encoder::create(w.bus, config_for(2000));
  ASSERT_TRUE(enc.ok());
  EncoderSample a = enc->read(w.t);
  w.advance(10'000'000);
  w.bus.fail_next(1);
  EncoderSample b = enc->read(w.t);
  EXPECT_TRUE(b.flags & kEncoderReadError);
  EXPECT_EQ(b.counters.read_errors, 1u);
  w.advance(10'000'000);
  EncoderSample c = enc->read(w.t);
  EXPECT_EQ(c.flags, 0u);
  // 20 ms of motion arrives with the next good reading.
  EXPECT_EQ(wrap_delta(a.left, c.left, 24), 20);
  EXPECT_EQ(wrap_delta(a.right, c.right, 24), -20);
}

TEST(Hctl1100Driver, ReadingsThatNeverAgreeAreAReadError) {
  // 2e7 counts/s with 1 us bus cycles: consecutive 3-cycle readings differ by ~60 counts, more
  // than the agree window of 16: the driver must refuse rather than guess.
  World w(Hctl1100Model::Latch::kNone, 2e7, 0, 1'000);
  auto enc = Hctl1100Encoder::create(w.bus, config_for(3e7));
  ASSERT_TRUE(enc.ok());
  const EncoderSample s = enc->read(w.t);
  EXPECT_TRUE(s.flags & kEncoderReadError);
  EXPECT_EQ(s.counters.read_errors, 1u);
}

TEST(Hctl1100Driver, ConfigurationIsChecked) {
  Hctl1100Model m;
  SimHctlBus one(&m);
  Hctl1100Config c;
  auto e1 = Hctl1100Encoder::create(one, c);  // unit_right = 1 does not exist on a 1-chip bus
  ASSERT_FALSE(e1.ok());
  EXPECT_NE(e1.error().message.find("unit_left/unit_right"), std::string::npos);
  Hctl1100Model m2;
  SimHctlBus two(&m, &m2);
  c.agree_window = 200;
  auto e2 = Hctl1100Encoder::create(two, c);
  ASSERT_FALSE(e2.ok());
  EXPECT_NE(e2.error().message.find("agree_window"), std::string::npos);
}

TEST(Hctl1100Driver, ReversedWheelCountsNegative) {
  World w(Hctl1100Model::Latch::kNone, 1000, 1000, 1'000);
  Hctl1100Config c = config_for(2000);
  c.reverse_right = true;
  auto enc = Hctl1100Encoder::create(w.bus, c);
  ASSERT_TRUE(enc.ok());
  const EncoderSample a = enc->read(w.t);
  w.advance(10'000'000);
  const EncoderSample b = enc->read(w.t);
  EXPECT_EQ(wrap_delta(a.left, b.left, 24), 10);
  EXPECT_EQ(wrap_delta(a.right, b.right, 24), -10);
}

// The firmware loop integrates the driver's readings; an injected jump leaves the pose alone
// and shows in the snapshot's flags and counters.
TEST(Hctl1100Driver, LoopIntegratesAndReportsJumps) {
  struct Clocked final : sim::BusCycleHook {
    Hctl1100Model l, r;
    sim::VirtualClock clock;
    void on_bus_cycle() noexcept override {
      // Both wheels at 1000 counts/s forward (a straight line).
      const auto n = static_cast<std::int64_t>(to_seconds(clock.now()) * 1000.0);
      l.follow(n);
      r.follow(n);
    }
  } world;
  SimHctlBus bus(&world.l, &world.r);
  bus.set_hook(&world);
  auto enc = Hctl1100Encoder::create(bus, config_for(5000));
  ASSERT_TRUE(enc.ok());
  // c_m = pi * 0.15 / (16 * 2048) = 1.438e-5 m per count.
  const auto k = Kinematics::create(KinematicParams{0.15, 2048, 16, 0.34, 0.34, 1.0, 1.0});
  ASSERT_TRUE(k.ok());
  auto loop = loop::OdometryLoop::create(loop::LoopConfig{100.0}, *k, *enc, world.clock);
  ASSERT_TRUE(loop.ok());
  (*loop)->start();
  for (int i = 0; i < 100; ++i) (*loop)->tick();  // 1 s
  world.l.inject_jump(100000);
  for (int i = 0; i < 100; ++i) (*loop)->tick();  // 2 s
  const loop::LoopSnapshot& s = (*loop)->snapshot();
  EXPECT_EQ(s.encoder_counters.implausible_jumps, 1u);
  // 2 s * 1000 counts/s * 1.438e-5 m = 0.02876 m, straight ahead; the jump would have added
  // 100000 counts (1.4 m) to the left wheel. One tick of the left wheel (10 counts) is given
  // up when re-basing.
  const double cm = 3.14159265358979 * 0.15 / (16 * 2048);
  EXPECT_NEAR(s.pose.x, 2000 * cm, 12 * cm);
  EXPECT_NEAR(s.pose.theta, 0.0, 12 * cm / 0.34);
}

}  // namespace
}  // namespace odo
