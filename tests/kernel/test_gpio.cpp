// Kernel tier: the libgpiod backends on real kernel GPIO chips (gpio-sim in the VM harness).
// Edges are driven through the simulator's sysfs `pull` attributes.
#include <gtest/gtest.h>

#include <chrono>
#include <functional>
#include <mutex>
#include <thread>

#include "gpio_sim.hpp"
#include "kernel_env.hpp"
#include "odo/drivers/gpio_quadrature.hpp"
#include "odo/drivers/gpiod_parallel_bus.hpp"
#include "odo/drivers/hctl1100_encoder.hpp"
#include "odo/hal/quadrature.hpp"
#include "odo/sim/hctl1100_model.hpp"

namespace odo::test {
namespace {

using namespace std::chrono_literals;

// FlowControl: the v1 uAPI of libgpiod 1.6 labels an edge rising or falling from the line level
// when the kernel's IRQ thread runs, and queues 16 events per line. On one emulated vCPU shared
// with the writer, a second edge of a line can come before that thread ran (a mislabelled
// edge, which the decoder reports as invalid). A test about exact decoding therefore writes
// the next edge only when the previous one has been read from the kernel. How fast the decoder
// can go on an unthrottled stream is what bench_gpio_edges measures.
struct FlowControl {
  std::function<std::uint64_t()> received;  // events the decoder has read from the kernel
  std::uint64_t written = 0;
  void before_edge() {
    const auto end = std::chrono::steady_clock::now() + 2s;
    while (received() < written && std::chrono::steady_clock::now() < end)
      std::this_thread::sleep_for(100us);
    ++written;
  }
};

// QuadWriter: moves a simulated encoder on lines a/b one quadrature state at a time.
struct QuadWriter {
  GpioSim& sim;
  int a, b;
  FlowControl* flow = nullptr;
  std::int64_t pos = 0;
  // step: one count forward (+1) or backward (-1): exactly one line changes.
  void step(int dir) {
    if (flow != nullptr) flow->before_edge();
    const QuadState from = quad_state_at(pos);
    pos += dir;
    const QuadState to = quad_state_at(pos);
    const QuadState changed = from ^ to;
    if (changed & 2u) {
      ASSERT_TRUE(sim.pull(a, (to & 2u) != 0));
    }
    if (changed & 1u) {
      ASSERT_TRUE(sim.pull(b, (to & 1u) != 0));
    }
  }
};

drivers::GpioQuadratureConfig quad_config(const GpioSim& sim) {
  drivers::GpioQuadratureConfig c;
  c.chip = sim.chip();
  c.left = {0, 1, 4, false};
  c.right = {2, 3, -1, false};
  c.consumer = "odo-test";
  return c;
}

TEST(GpioQuadratureKernel, ThousandsOfEdgesBothDirectionsCountExactly) {
  ODO_REQUIRE_VM();
  GpioSim sim("odo_quad_exact", 5);
  auto enc = drivers::GpioQuadratureEncoder::open(quad_config(sim));
  ASSERT_TRUE(enc.ok()) << enc.error().message;
  auto& e = **enc;
  FlowControl flow{[&] { return e.wheel(0).received + e.wheel(1).received; }};
  QuadWriter left{sim, 0, 1, &flow};
  QuadWriter right{sim, 2, 3, &flow};
  // Left: 3000 forward, 1200 back; right: 2000 back, 500 forward; interleaved edge by edge.
  for (int i = 0; i < 3000; ++i) {
    left.step(+1);
    if (i < 2000) right.step(-1);
  }
  for (int i = 0; i < 1200; ++i) {
    left.step(-1);
    if (i < 500) right.step(+1);
  }
  const std::uint64_t edges = 3000 + 1200 + 2000 + 500;
  ASSERT_TRUE(wait_until([&] { return e.wheel(0).edges + e.wheel(1).edges >= edges; }, 20))
      << "edges seen " << e.wheel(0).edges + e.wheel(1).edges << " of " << edges;
  std::this_thread::sleep_for(100ms);  // nothing more may arrive
  const EncoderSample s = e.read(0);
  EXPECT_EQ(s.left, 1800);
  EXPECT_EQ(s.right, -1500);
  EXPECT_EQ(s.counters.invalid_transitions, 0u);
  EXPECT_EQ(s.flags, 0u);
  EXPECT_EQ(e.wheel(0).edges + e.wheel(1).edges, edges);
}

TEST(GpioQuadratureKernel, IndexLineLatchesTheCount) {
  ODO_REQUIRE_VM();
  GpioSim sim("odo_quad_index", 5);
  auto enc = drivers::GpioQuadratureEncoder::open(quad_config(sim));
  ASSERT_TRUE(enc.ok()) << enc.error().message;
  auto& e = **enc;
  FlowControl flow{[&] { return e.wheel(0).received; }};
  QuadWriter left{sim, 0, 1, &flow};
  for (int i = 0; i < 37; ++i) left.step(+1);
  ASSERT_TRUE(wait_until([&] { return e.wheel(0).count == 37; }, 5));
  ASSERT_TRUE(sim.pull(4, true));  // index pulse
  ASSERT_TRUE(sim.pull(4, false));
  for (int i = 0; i < 5; ++i) left.step(+1);
  ASSERT_TRUE(wait_until([&] { return e.wheel(0).count == 42; }, 5));
  EXPECT_EQ(e.wheel(0).index_pulses, 1u);
  EXPECT_EQ(e.wheel(0).index_count, 37);
}

// Edges lost in the kernel (its per-line event queue holds 16 events) are detected and counted
// as invalid transitions, never turned into motion; counting goes on correctly afterwards.
TEST(GpioQuadratureKernel, LostEventsAreDetectedAndNotCounted) {
  ODO_REQUIRE_VM();
  GpioSim sim("odo_quad_lost", 5);
  auto enc = drivers::GpioQuadratureEncoder::open(quad_config(sim));
  ASSERT_TRUE(enc.ok()) << enc.error().message;
  auto& e = **enc;
  // Control: two legal steps while the reader is held fit in the queue and count normally.
  e.hold(true);
  std::this_thread::sleep_for(20ms);
  QuadWriter left{sim, 0, 1};
  left.step(+1);
  left.step(+1);
  e.hold(false);
  ASSERT_TRUE(wait_until([&] { return e.wheel(0).count == 2; }, 5));
  EXPECT_EQ(e.wheel(0).invalid, 0u);

  // Injection: A toggles 41 times while the reader is held. The kernel keeps 16 events and
  // drops the rest; when its IRQ thread kept up, the 16 alternate and cancel while A ends on
  // the opposite level: the decoder must notice (idle check) and count it as invalid, without
  // motion. When the IRQ thread coalesced edges, the delivered events can happen to agree with
  // the final levels and nothing is detectable: so up to 5 rounds, each of which may move the
  // count by at most the one step the lines really moved.
  bool a = (quad_state_at(left.pos) & 2u) != 0;
  const bool b = (quad_state_at(left.pos) & 1u) != 0;
  int rounds = 0;
  while (e.wheel(0).invalid == 0 && rounds < 5) {
    ++rounds;
    const std::int64_t before = e.wheel(0).count;
    e.hold(true);
    std::this_thread::sleep_for(20ms);
    for (int i = 1; i <= 41; ++i) ASSERT_TRUE(sim.pull(0, (i % 2 == 1) ? !a : a));
    a = !a;
    e.hold(false);
    // Quiet for longer than the idle check (50 ms) plus its 2 ms confirmation.
    std::uint64_t seen = e.wheel(0).received;
    do {
      seen = e.wheel(0).received;
      std::this_thread::sleep_for(300ms);
    } while (e.wheel(0).received != seen);
    EXPECT_LE(std::llabs(e.wheel(0).count - before), 1) << "round " << rounds;
  }
  ASSERT_GE(e.wheel(0).invalid, 1u) << "lost edges never detected in " << rounds << " rounds";
  const EncoderSample s = e.read(0);
  EXPECT_TRUE(s.flags & kEncoderInvalidTransition);
  EXPECT_GE(s.counters.invalid_transitions, 1u);

  // From the adopted state, 100 legal steps count exactly 100.
  const std::int64_t base = e.wheel(0).count;
  const std::uint64_t inv = e.wheel(0).invalid;
  // The writer's idea of the position: the levels the lines are at now.
  left.pos = 0;
  const QuadState now = quad_state(a, b);
  while (quad_state_at(left.pos) != now) ++left.pos;
  FlowControl flow{[&] { return e.wheel(0).received; }, e.wheel(0).received};
  left.flow = &flow;
  for (int i = 0; i < 100; ++i) left.step(+1);
  ASSERT_TRUE(wait_until([&] { return e.wheel(0).count == base + 100; }, 5))
      << "count " << e.wheel(0).count << " expected " << base + 100;
  EXPECT_EQ(e.wheel(0).invalid, inv);
}

// Issue 38: two A/B pairs per side on one gpio-sim chip (left 0/1 and 4/5, right 2/3 and 6/7).
// Each side is the mean of its wheels; a wheel whose lines give an illegal transition (events
// lost in the kernel while A toggles, as above) is dropped for that read and the other wheel
// carries the side; it rejoins from the next read.
TEST(GpioQuadratureKernel, TwoPairsPerSideMeanAndAWheelWithIllegalTransitionsIsDropped) {
  ODO_REQUIRE_VM();
  GpioSim sim("odo_quad_two", 8);
  drivers::GpioQuadratureConfig c = quad_config(sim);
  c.left.index = -1;
  c.wheels.wheels_per_side = 2;
  c.more_left[0] = {4, 5, -1, false};
  c.more_right[0] = {6, 7, -1, false};
  auto enc = drivers::GpioQuadratureEncoder::open(c);
  ASSERT_TRUE(enc.ok()) << enc.error().message;
  auto& e = **enc;
  EXPECT_EQ(e.counter_bits(), 64);
  auto received = [&] {
    std::uint64_t n = 0;
    for (int w = 0; w < 4; ++w) n += e.wheel(w).received;
    return n;
  };
  FlowControl flow{received};
  QuadWriter l1{sim, 0, 1, &flow}, r1{sim, 2, 3, &flow}, l2{sim, 4, 5, &flow}, r2{sim, 6, 7, &flow};
  EncoderSample s = e.read(0);  // every wheel's reference: the sides start at 0
  EXPECT_EQ(s.flags, 0u);
  EXPECT_EQ(s.left, 0);
  // Left wheels +100 and +200: mean 150; right -40 and -60: -50.
  for (int i = 0; i < 200; ++i) {
    if (i < 100) l1.step(+1);
    l2.step(+1);
    if (i < 40) r1.step(-1);
    if (i < 60) r2.step(-1);
  }
  ASSERT_TRUE(wait_until([&] { return e.wheel(2).count == 200 && e.wheel(3).count == -60; }, 20));
  ASSERT_TRUE(wait_until([&] { return e.wheel(0).count == 100 && e.wheel(1).count == -40; }, 5));
  s = e.read(0);
  EXPECT_EQ(s.flags, 0u);
  EXPECT_EQ(s.left, 150);
  EXPECT_EQ(s.right, -50);
  // Left wheel 1 moves +30; left wheel 2's A toggles 41 times while the reader is held, until
  // the decoder reports an invalid transition on it (up to 5 rounds, see above).
  for (int i = 0; i < 30; ++i) l1.step(+1);
  ASSERT_TRUE(wait_until([&] { return e.wheel(0).count == 130; }, 5));
  bool a = (quad_state_at(l2.pos) & 2u) != 0;
  const bool b = (quad_state_at(l2.pos) & 1u) != 0;
  for (int round = 0; e.wheel(2).invalid == 0 && round < 5; ++round) {
    e.hold(true);
    std::this_thread::sleep_for(20ms);
    for (int i = 1; i <= 41; ++i) ASSERT_TRUE(sim.pull(4, (i % 2 == 1) ? !a : a));
    a = !a;
    e.hold(false);
    std::uint64_t seen = 0;
    do {
      seen = e.wheel(2).received;
      std::this_thread::sleep_for(300ms);
    } while (e.wheel(2).received != seen);
  }
  ASSERT_GE(e.wheel(2).invalid, 1u) << "no illegal transition detected in 5 rounds";
  EXPECT_EQ(e.wheel(0).invalid, 0u);
  // The read: left wheel 2 dropped, the side moved by wheel 1's +30 alone: 150 + 30.
  s = e.read(0);
  EXPECT_EQ(s.flags & (kEncoderWheelDropped | kEncoderInvalidTransition),
            kEncoderWheelDropped | kEncoderInvalidTransition);
  EXPECT_EQ(s.flags & (kEncoderStaleLeft | kEncoderStaleRight), 0u);
  EXPECT_EQ(s.left, 180);
  EXPECT_EQ(s.right, -50);
  EXPECT_EQ(s.counters.wheel_drops, 1u);
  // Next read: clean again, it takes its new reference; then both left wheels +20: 200.
  s = e.read(0);
  EXPECT_EQ(s.flags, 0u);
  EXPECT_EQ(s.left, 180);
  l2.pos = 0;
  while (quad_state_at(l2.pos) != quad_state(a, b)) ++l2.pos;
  flow.written = received();
  const std::int64_t w1 = e.wheel(0).count, w2 = e.wheel(2).count;
  for (int i = 0; i < 20; ++i) {
    l1.step(+1);
    l2.step(+1);
  }
  ASSERT_TRUE(
      wait_until([&] { return e.wheel(0).count == w1 + 20 && e.wheel(2).count == w2 + 20; }, 5));
  s = e.read(0);
  EXPECT_EQ(s.flags, 0u);
  EXPECT_EQ(s.left, 200);
}

TEST(GpioQuadratureKernel, BadLinesAreClearErrors) {
  ODO_REQUIRE_VM();
  GpioSim sim("odo_quad_bad", 5);
  auto c = quad_config(sim);
  c.right.b = 40;  // the chip has 5 lines
  auto enc = drivers::GpioQuadratureEncoder::open(c);
  ASSERT_FALSE(enc.ok());
  EXPECT_NE(enc.error().message.find("line 40 (right b)"), std::string::npos)
      << enc.error().message;
  c.chip = "/dev/gpiochip-none";
  auto enc2 = drivers::GpioQuadratureEncoder::open(c);
  ASSERT_FALSE(enc2.ok());
  EXPECT_NE(enc2.error().message.find("gpiochip-none"), std::string::npos);
}

// The HCTL-1100 driver over the libgpiod bus on gpio-sim lines. ChipResponder plays the chip:
// told by the bus after each phase (BusPhaseHook, instead of a wall-clock race against an
// emulated CPU), it looks only at the lines through sysfs: which /CS is low, the address on
// AD0..7 while ALE has fallen, and answers from the register model through the pull attributes
// once AD are inputs and /OE is low.
class ChipResponder final : public drivers::BusPhaseHook {
 public:
  // Lines: AD0..7 = 0..7, ALE 8, OE 9 (/OE), RW 10, CS0 11 (/CS), CS1 12 (/CS).
  ChipResponder(GpioSim& sim, sim::Hctl1100Model& u0, sim::Hctl1100Model& u1)
      : sim_(sim), units_{&u0, &u1} {}
  void on_phase(int, Phase phase) noexcept override {
    switch (phase) {
      case Phase::kAddressLatched: {
        // /CS of exactly one chip low, ALE low, /OE high, R/W high (read); AD drive the address.
        selected_ = -1;
        if (sim_.value(11) == 0 && sim_.value(12) == 1) selected_ = 0;
        if (sim_.value(12) == 0 && sim_.value(11) == 1) selected_ = 1;
        if (sim_.value(8) != 0 || sim_.value(9) != 1 || sim_.value(10) != 1) selected_ = -1;
        addr_ = 0;
        for (int i = 0; i < 8; ++i) addr_ |= (sim_.value(i) == 1 ? 1 : 0) << i;
        addresses_.push_back(selected_ < 0 ? -1 : addr_);
        break;
      }
      case Phase::kOutputEnabled: {
        if (selected_ < 0 || sim_.value(9) != 0) {
          protocol_errors_++;
          break;
        }
        const std::uint8_t data =
            units_[selected_]->read_register(static_cast<std::uint8_t>(addr_));
        for (int i = 0; i < 8; ++i) sim_.pull(i, ((data >> i) & 1) != 0);
        break;
      }
      case Phase::kReleased:
        if (sim_.value(11) != 1 || sim_.value(12) != 1 || sim_.value(9) != 1) protocol_errors_++;
        selected_ = -1;
        break;
    }
  }
  const std::vector<int>& addresses() const { return addresses_; }
  int protocol_errors() const { return protocol_errors_; }

 private:
  GpioSim& sim_;
  sim::Hctl1100Model* units_[2];
  int selected_ = -1;
  int addr_ = 0;
  int protocol_errors_ = 0;
  std::vector<int> addresses_;
};

drivers::GpiodBusConfig bus_config(const GpioSim& sim) {
  drivers::GpiodBusConfig c;
  c.chip = sim.chip();
  c.ad = {0, 1, 2, 3, 4, 5, 6, 7};
  c.ale = 8;
  c.oe = 9;
  c.rw = 10;
  c.cs = {11, 12};
  c.settle = 0;  // the responder is told each phase through the hook
  c.consumer = "odo-test";
  return c;
}

TEST(HctlOverGpiodBusKernel, DriverReadsTheModelThroughGpioLines) {
  ODO_REQUIRE_VM();
  GpioSim sim("odo_hctl_bus", 13);
  sim::Hctl1100Model left(sim::Hctl1100Model::Latch::kLsbLatch);
  sim::Hctl1100Model right(sim::Hctl1100Model::Latch::kLsbLatch);
  left.preset(123456);    // 0x01E240
  right.preset(-654321);  // 0xF6040F
  ChipResponder chip(sim, left, right);
  drivers::GpiodBusConfig bc = bus_config(sim);
  bc.hook = &chip;
  auto bus = drivers::GpiodParallelBus::open(bc);
  ASSERT_TRUE(bus.ok()) << bus.error().message;
  drivers::Hctl1100Config hc;
  hc.max_counts_per_s = 10000;
  auto enc = drivers::Hctl1100Encoder::create(**bus, hc);
  ASSERT_TRUE(enc.ok()) << enc.error().message;
  const EncoderSample a = enc->read(0);
  EXPECT_EQ(a.flags, 0u);
  EXPECT_EQ(a.left, 123456);
  EXPECT_EQ(a.right, -654321);
  // Every cycle drove a position register address, LSB first: 14h, 13h, 12h.
  const std::vector<int> seen = chip.addresses();
  EXPECT_EQ(chip.protocol_errors(), 0);
  ASSERT_EQ(seen.size(), 12u);  // 2 wheels x 2 agreeing readings x 3 bytes
  for (std::size_t i = 0; i < seen.size(); ++i) EXPECT_EQ(seen[i], 0x14 - int(i % 3)) << i;
  // The wheel moves 300 counts forward across the LSB roll-over (0x40 + 300 = 0x16C).
  left.follow(300);
  const EncoderSample b = enc->read(1'000'000'000);
  EXPECT_EQ(b.flags, 0u);
  EXPECT_EQ(b.left, 123756);
  EXPECT_EQ(b.right, -654321);
  // Idle state after the cycles: /CS and /OE released (high), ALE low.
  EXPECT_EQ(sim.value(11), 1);
  EXPECT_EQ(sim.value(12), 1);
  EXPECT_EQ(sim.value(9), 1);
  EXPECT_EQ(sim.value(8), 0);
}

}  // namespace
}  // namespace odo::test
