// CAN encoder counts (issue 5, backend 3): the pure frame decoder with hand-built frames, and
// CanEncoderSource against sim_hal's SimCanPort for every fault path (stale, recovery,
// implausible jump, floods beyond the per-read cap, short frames, remote requests).
#include <gtest/gtest.h>

#include <cstdint>

#include "can_frame_bytes.hpp"
#include "odo/drivers/can_encoder.hpp"
#include "odo/odometry/count_delta.hpp"
#include "odo/sim/sim_can_bus.hpp"
#include "odo/sim/sim_odrive.hpp"

namespace odo::drivers {
namespace {

constexpr TimeNs kMs = 1'000'000;

using test::frame;

// odrive: a Get_Encoder_Count reply of `node` with shadow count `shadow` (little endian int32
// at byte 0) and count-in-CPR 0x55 at byte 4 (never read).
CanFrame odrive(std::uint32_t node, std::int32_t shadow, TimeNs stamp) {
  const auto u = static_cast<std::uint32_t>(shadow);
  return frame(
      (node << 5) | 0x00A,
      {static_cast<std::uint8_t>(u), static_cast<std::uint8_t>(u >> 8),
       static_cast<std::uint8_t>(u >> 16), static_cast<std::uint8_t>(u >> 24), 0x55, 0, 0, 0},
      stamp);
}

TEST(CanDecode, OdriveLayoutIsShadowCountOfCommand0x00A) {
  const CanCountLayout l = odrive_count_layout(3);
  // node 3: 3 << 5 = 0x60, | 0x00A = 0x06A.
  EXPECT_EQ(l.id, 0x06Au);
  EXPECT_FALSE(l.extended);
  EXPECT_EQ(l.byte_offset, 0);
  EXPECT_EQ(l.width_bits, 32);
  EXPECT_TRUE(l.is_signed);
  EXPECT_FALSE(l.big_endian);
  std::int64_t v = 0;
  // bytes 0x10 0x32 0x54 0x76 little endian = 0x76543210 = 1985229328.
  ASSERT_EQ(decode_count(frame(0x06A, {0x10, 0x32, 0x54, 0x76, 0xFF, 0xFF, 0xFF, 0xFF}), l, v),
            CanDecode::kOk);
  EXPECT_EQ(v, 1985229328);
  // 0xFFFFFFFE as int32 = -2.
  ASSERT_EQ(decode_count(frame(0x06A, {0xFE, 0xFF, 0xFF, 0xFF, 0, 0, 0, 0}), l, v), CanDecode::kOk);
  EXPECT_EQ(v, -2);
}

TEST(CanDecode, ByteOrderSignednessWidthOffset) {
  const CanFrame f = frame(0x123, {0x00, 0x80, 0x01, 0xFF, 0xFE, 0x12, 0x34, 0x56});
  CanCountLayout l;
  l.id = 0x123;
  std::int64_t v = 0;
  // 16 bits at offset 1, little endian: bytes 0x80 0x01 -> 0x0180 = 384 (signed or not).
  l.byte_offset = 1;
  l.width_bits = 16;
  ASSERT_EQ(decode_count(f, l, v), CanDecode::kOk);
  EXPECT_EQ(v, 384);
  // Same bytes big endian: 0x8001 = 32769 unsigned, 32769 - 65536 = -32767 signed.
  l.big_endian = true;
  l.is_signed = false;
  ASSERT_EQ(decode_count(f, l, v), CanDecode::kOk);
  EXPECT_EQ(v, 32769);
  l.is_signed = true;
  ASSERT_EQ(decode_count(f, l, v), CanDecode::kOk);
  EXPECT_EQ(v, -32767);
  // 24 bits at offset 3, big endian: 0xFF 0xFE 0x12 = 0xFFFE12 = 16776722 unsigned;
  // signed: 16776722 - 2^24 = 16776722 - 16777216 = -494.
  l.byte_offset = 3;
  l.width_bits = 24;
  ASSERT_EQ(decode_count(f, l, v), CanDecode::kOk);
  EXPECT_EQ(v, -494);
  l.is_signed = false;
  ASSERT_EQ(decode_count(f, l, v), CanDecode::kOk);
  EXPECT_EQ(v, 16776722);
  // 64 bits little endian: 0x56341 2FEFF018000 -> bytes reversed = 0x563412FEFF018000.
  l.byte_offset = 0;
  l.width_bits = 64;
  l.big_endian = false;
  l.is_signed = true;
  ASSERT_EQ(decode_count(f, l, v), CanDecode::kOk);
  EXPECT_EQ(static_cast<std::uint64_t>(v), 0x563412FEFF018000ull);
  // 48 bits at offset 2, little endian: bytes 01 FF FE 12 34 56 -> 0x563412FEFF01, positive.
  l.byte_offset = 2;
  l.width_bits = 48;
  ASSERT_EQ(decode_count(f, l, v), CanDecode::kOk);
  EXPECT_EQ(v, 0x563412FEFF01ll);
}

TEST(CanDecode, WrongIdRemoteAndShortFramesAreNotCounts) {
  const CanCountLayout l = odrive_count_layout(1);  // id 0x02A
  std::int64_t v = 77;
  EXPECT_EQ(decode_count(frame(0x02B, {1, 2, 3, 4, 5, 6, 7, 8}), l, v), CanDecode::kOtherId);
  // The same number as a 29-bit id is another identifier.
  EXPECT_EQ(decode_count(frame(0x02A, {1, 2, 3, 4}, 0, true), l, v), CanDecode::kOtherId);
  CanFrame rtr = frame(0x02A, {});
  rtr.rtr = true;
  rtr.len = 8;
  EXPECT_EQ(decode_count(rtr, l, v), CanDecode::kRemote);
  // DLC 3 < offset 0 + 4 bytes.
  EXPECT_EQ(decode_count(frame(0x02A, {1, 2, 3}), l, v), CanDecode::kShortFrame);
  // A DLC above 8 is never trusted.
  CanFrame bad = frame(0x02A, {1, 2, 3, 4});
  bad.len = 15;
  EXPECT_EQ(decode_count(bad, l, v), CanDecode::kShortFrame);
  EXPECT_EQ(v, 77);  // untouched
  // DLC 4 is enough for the shadow count (the count-in-CPR is not needed).
  ASSERT_EQ(decode_count(frame(0x02A, {5, 0, 0, 0}), l, v), CanDecode::kOk);
  EXPECT_EQ(v, 5);
}

TEST(CanDecode, LayoutChecksNameTheProblem) {
  CanCountLayout l;
  l.id = 0x800;  // 2048 > 0x7FF
  EXPECT_NE(check_layout(l).error().message.find("does not fit 11 bits"), std::string::npos);
  l.extended = true;
  EXPECT_TRUE(check_layout(l).ok());
  l.id = 0x20000000;  // 2^29
  EXPECT_NE(check_layout(l).error().message.find("does not fit 29 bits"), std::string::npos);
  l.id = 1;
  l.width_bits = 8;
  EXPECT_NE(check_layout(l).error().message.find("width 8"), std::string::npos);
  l.width_bits = 20;
  EXPECT_FALSE(check_layout(l).ok());
  l.width_bits = 32;
  l.byte_offset = 5;  // 5 + 4 = 9 > 8
  EXPECT_NE(check_layout(l).error().message.find("byte offset 5 + 4 bytes"), std::string::npos);
  l.byte_offset = 4;
  EXPECT_TRUE(check_layout(l).ok());
}

struct CanEncoder : ::testing::Test {
  sim::SimCanPort port{8, 512};
  CanEncoderConfig cfg = [] {
    CanEncoderConfig c;
    c.left = odrive_count_layout(0);   // id 0x00A
    c.right = odrive_count_layout(1);  // id 0x02A
    c.timeout = 50 * kMs;
    c.max_counts_per_s = 10'000;
    return c;
  }();
  CanEncoderSource make() {
    auto s = CanEncoderSource::create(port, cfg);
    EXPECT_TRUE(s.ok());
    return std::move(s).value();
  }
};

// A read before the wheels' first frames reports them as 0 and stale; from the first frame on
// they are the controller's counts (the loop takes the first fresh count as its reference).
TEST_F(CanEncoder, BeforeTheFirstFrameStaleAndZeroThenTheControllersCounts) {
  CanEncoderSource enc = make();
  EXPECT_EQ(enc.counter_bits(), 32);
  EncoderSample s = enc.read(10 * kMs);
  EXPECT_EQ(s.flags, kEncoderStaleLeft | kEncoderStaleRight);
  EXPECT_EQ(s.left, 0);
  EXPECT_EQ(s.right, 0);
  EXPECT_EQ(s.counters.stale_events, 0u);  // the start-up state is not an event
  port.inject(odrive(0, 1000, 15 * kMs));
  port.inject(odrive(1, -5000, 15 * kMs));
  s = enc.read(20 * kMs);
  EXPECT_EQ(s.flags, 0u);
  EXPECT_EQ(s.left, 1000);  // as sent, no reference subtracted
  EXPECT_EQ(s.right, -5000);
  // The sample time is the frames' (issue 39: both counts at one instant), not the read's.
  EXPECT_EQ(s.stamp, 15 * kMs);
  // 10 ms later: +50 and -30 counts (well under 10 000 counts/s * 10 ms = 100).
  port.inject(odrive(0, 1050, 25 * kMs));
  port.inject(odrive(1, -5030, 25 * kMs));
  s = enc.read(30 * kMs);
  EXPECT_EQ(s.flags, 0u);
  EXPECT_EQ(s.left, 1050);
  EXPECT_EQ(s.right, -5030);
}

TEST_F(CanEncoder, FramesBeforeTheFirstReadGiveTheControllersOwnCounts) {
  port.inject(odrive(0, 1000, 15 * kMs));
  port.inject(odrive(1, -5000, 15 * kMs));
  CanEncoderSource enc = make();
  EncoderSample s = enc.read(20 * kMs);
  EXPECT_EQ(s.flags, 0u);
  EXPECT_EQ(s.left, 1000);  // the shadow counts as sent: no reference subtracted
  EXPECT_EQ(s.right, -5000);
  port.inject(odrive(0, 1050, 25 * kMs));
  port.inject(odrive(1, -5030, 25 * kMs));
  s = enc.read(30 * kMs);
  EXPECT_EQ(s.left, 1050);
  EXPECT_EQ(s.right, -5030);
}

TEST_F(CanEncoder, CountsAreContinuousAcrossARestartOfTheReader) {
  // Issue 17: a restarted daemon (a new source on the same bus) reads the controllers' counters
  // where the old one left them, plus what the wheels moved meanwhile. Right reversed: the
  // negation is the same in both runs.
  cfg.reverse_right = true;
  std::int64_t left_before = 0, right_before = 0;
  {
    CanEncoderSource first = make();
    port.inject(odrive(0, 70'000, 10 * kMs));
    port.inject(odrive(1, 70'000, 10 * kMs));
    const EncoderSample s = first.read(10 * kMs);
    left_before = s.left;
    right_before = s.right;
  }
  EXPECT_EQ(left_before, 70'000);
  EXPECT_EQ(right_before, -70'000);
  // Down for 1 s while the controllers count on: +9000 and +8000 counts (under the 10 000
  // counts/s limit; the new source has no previous frame to check a step against).
  port.inject(odrive(0, 79'000, 1010 * kMs));
  port.inject(odrive(1, 78'000, 1010 * kMs));
  CanEncoderSource second = make();
  const EncoderSample s = second.read(1010 * kMs);
  EXPECT_EQ(s.flags, 0u);
  EXPECT_EQ(s.left, 79'000);
  EXPECT_EQ(s.right, -78'000);
  EXPECT_EQ(wrap_delta(left_before, s.left, 32), 9000);
  EXPECT_EQ(wrap_delta(right_before, s.right, 32), -8000);
}

TEST_F(CanEncoder, SixteenBitUnsignedCountsAreSignExtendedForTheWrapRule) {
  // A generic 16-bit unsigned counter (little endian at byte 0, ids 0x120/0x121). 0xFFF0 =
  // 65520 is reported as the 16-bit counter the loop sees: 65520 - 65536 = -16; 0x0010 after
  // it is +32 counts by the wrap rule (16 - (-16)), the same in every run of the daemon.
  cfg.left = CanCountLayout{0x120, false, 0, 16, false, false};
  cfg.right = CanCountLayout{0x121, false, 0, 16, false, false};
  CanEncoderSource enc = make();
  EXPECT_EQ(enc.counter_bits(), 16);
  port.inject(frame(0x120, {0xF0, 0xFF}, 10 * kMs));
  port.inject(frame(0x121, {0x05, 0x00}, 10 * kMs));
  const EncoderSample a = enc.read(10 * kMs);
  EXPECT_EQ(a.left, -16);
  EXPECT_EQ(a.right, 5);
  port.inject(frame(0x120, {0x10, 0x00}, 20 * kMs));
  port.inject(frame(0x121, {0x01, 0x00}, 20 * kMs));
  const EncoderSample b = enc.read(20 * kMs);
  EXPECT_EQ(b.flags, 0u);
  EXPECT_EQ(b.left, 16);
  EXPECT_EQ(b.right, 1);
  EXPECT_EQ(wrap_delta(a.left, b.left, 16), 32);
  EXPECT_EQ(wrap_delta(a.right, b.right, 16), -4);
}

TEST_F(CanEncoder, StoppedWheelIsStaleAfterTheTimeoutOnceAndRecoversWithRealMotion) {
  CanEncoderSource enc = make();
  port.inject(odrive(0, 0, 0 * kMs + 1));
  port.inject(odrive(1, 0, 0 * kMs + 1));
  EXPECT_EQ(enc.read(1 * kMs).flags, 0u);
  // Only the right wheel keeps sending, every 10 ms; the left's last frame is at 1 ns.
  std::uint32_t flags = 0;
  for (TimeNs t = 10 * kMs; t <= 100 * kMs; t += 10 * kMs) {
    port.inject(odrive(1, static_cast<std::int32_t>(t / kMs), t));
    flags = enc.read(t).flags;
    // Stale once now - 1 ns > 50 ms, i.e. from t = 60 ms on (50 ms is 1 ns short of it).
    EXPECT_EQ(flags, t >= 60 * kMs ? kEncoderStaleLeft : 0u) << t;
  }
  EncoderSample s = enc.read(100 * kMs);
  EXPECT_EQ(s.counters.stale_events, 1u);  // one transition, however long it lasts
  EXPECT_EQ(s.left, 0);                    // the last count is kept
  // The left wheel comes back at 200 ms having moved 900 counts: 199 ms at up to 10 000
  // counts/s allows 1990 (+ slack), so this is real motion and is integrated.
  port.inject(odrive(0, 900, 200 * kMs));
  s = enc.read(200 * kMs);
  EXPECT_EQ(s.flags & kEncoderStaleLeft, 0u);
  EXPECT_EQ(s.flags & kEncoderImplausibleJump, 0u);
  EXPECT_EQ(s.left, 900);
  // Stops again: a second event.
  s = enc.read(260 * kMs);
  EXPECT_NE(s.flags & kEncoderStaleLeft, 0u);
  EXPECT_EQ(s.counters.stale_events, 3u);  // + the right wheel, silent since 100 ms
}

TEST_F(CanEncoder, ImplausibleJumpIsReportedNotIntegrated) {
  CanEncoderSource enc = make();
  port.inject(odrive(0, 100, 10 * kMs));
  port.inject(odrive(1, 100, 10 * kMs));
  enc.read(10 * kMs);
  // 10 ms later the left count leaps by 500: the limit is 10 000 * (0.010 + 0.005 latency
  // slack) + 1 = 151 counts.
  port.inject(odrive(0, 600, 20 * kMs));
  port.inject(odrive(1, 240, 20 * kMs));  // right: +140 < 151, plausible
  EncoderSample s = enc.read(20 * kMs);
  EXPECT_EQ(s.flags, static_cast<std::uint32_t>(kEncoderImplausibleJump));
  EXPECT_EQ(s.left, 100);   // not integrated: the count before the jump
  EXPECT_EQ(s.right, 240);  // +140
  EXPECT_EQ(s.counters.implausible_jumps, 1u);
  // Motion after the jump counts from the new base: 600 -> 640 is +40, 100 + 40 = 140 (the
  // right wheel's frame brings the common instant to 30 ms).
  port.inject(odrive(0, 640, 30 * kMs));
  port.inject(odrive(1, 240, 30 * kMs));
  s = enc.read(30 * kMs);
  EXPECT_EQ(s.flags, 0u);
  EXPECT_EQ(s.left, 140);
}

// Issue 39: the limit is measured between the frames' own stamps, not between the reads that
// took them. Frame A of the left wheel arrives at 10 ms but is read late, at 19 ms; frame B
// arrives 13 ms after A (at 23 ms) and is read at once. Limit: 10 000 * (0.013 + 0.005) + 1 =
// 181 counts. Between the reads only 4 ms passed, which would allow 10 000 * 0.009 + 1 = 91.
TEST_F(CanEncoder, JumpLimitUsesTheFramesStampsLateThenEarly) {
  for (const std::int32_t step : {180, 181, 182}) {
    sim::SimCanPort fresh{8, 512};
    auto made = CanEncoderSource::create(fresh, cfg);
    ASSERT_TRUE(made.ok());
    CanEncoderSource enc = std::move(made).value();
    fresh.inject(odrive(0, 0, 1 * kMs));
    fresh.inject(odrive(1, 0, 1 * kMs));
    enc.read(1 * kMs);
    fresh.inject(odrive(0, 100, 10 * kMs));
    fresh.inject(odrive(1, 0, 10 * kMs));
    EXPECT_EQ(enc.read(19 * kMs).flags, 0u);  // 100 counts in 9 ms: under 10 000 * 0.014 + 1
    fresh.inject(odrive(0, 100 + step, 23 * kMs));
    fresh.inject(odrive(1, 0, 23 * kMs));
    const EncoderSample s = enc.read(23 * kMs);
    // 180 and 181 are within the limit (|step| > 181 is the test), 182 is not.
    EXPECT_EQ(s.flags, step <= 181 ? 0u : static_cast<std::uint32_t>(kEncoderImplausibleJump))
        << step;
    EXPECT_EQ(s.left, step <= 181 ? 100 + step : 100) << step;
    EXPECT_EQ(s.left_rejected, step <= 181 ? 0 : step) << step;
  }
}

// Issue 39: one instant for both wheels. The left wheel's frames every 10 ms, the right's late:
// its frame for 20 ms is missing at the read at 20 ms. The sample time is the right's newest
// frame (10 ms) and the left count is the one at 10 ms, not the newer one.
TEST_F(CanEncoder, BothWheelsAtTheOlderNewestFrameInterpolated) {
  CanEncoderSource enc = make();
  port.inject(odrive(0, 0, 0 * kMs + 1));
  port.inject(odrive(1, 0, 0 * kMs + 1));
  enc.read(1 * kMs);
  port.inject(odrive(0, 50, 10 * kMs));
  port.inject(odrive(1, 40, 10 * kMs));
  port.inject(odrive(0, 100, 20 * kMs));
  EncoderSample s = enc.read(20 * kMs);
  EXPECT_EQ(s.stamp, 10 * kMs);
  EXPECT_EQ(s.left, 50);
  EXPECT_EQ(s.right, 40);
  // The right's next frame, stamped 15 ms (out of phase with the left), count 60: the common
  // instant is 15 ms, the left interpolated halfway between 50 (10 ms) and 100 (20 ms) = 75.
  port.inject(odrive(1, 60, 15 * kMs));
  s = enc.read(21 * kMs);
  EXPECT_EQ(s.stamp, 15 * kMs);
  EXPECT_EQ(s.left, 75);
  EXPECT_EQ(s.right, 60);
  // Three periods late, then all at once: right frames 25, 35, 45 ms; left 30, 40 ms. Instant:
  // min(40, 45) = 40 ms; left 40 ms exact = 160; right between 35 ms (90) and 45 ms (110): 100.
  port.inject(odrive(0, 130, 30 * kMs));
  port.inject(odrive(0, 160, 40 * kMs));
  port.inject(odrive(1, 70, 25 * kMs));
  port.inject(odrive(1, 90, 35 * kMs));
  port.inject(odrive(1, 110, 45 * kMs));
  s = enc.read(46 * kMs);
  EXPECT_EQ(s.flags, 0u);
  EXPECT_EQ(s.stamp, 40 * kMs);
  EXPECT_EQ(s.left, 160);
  EXPECT_EQ(s.right, 100);
}

TEST_F(CanEncoder, Int32WrapIsMotionNotAJump) {
  CanEncoderSource enc = make();
  // 2147483600 -> -2147483616: as int32 steps, -2147483616 - 2147483600 = -4294967216,
  // + 2^32 = +80 counts.
  port.inject(odrive(0, 2147483600, 10 * kMs));
  port.inject(odrive(1, 0, 10 * kMs));
  const EncoderSample a = enc.read(10 * kMs);
  EXPECT_EQ(a.left, 2147483600);
  port.inject(odrive(0, -2147483616, 20 * kMs));
  port.inject(odrive(1, 0, 20 * kMs));
  const EncoderSample s = enc.read(20 * kMs);
  EXPECT_EQ(s.flags, 0u);  // not flagged as a jump
  EXPECT_EQ(s.left, -2147483616);
  EXPECT_EQ(wrap_delta(a.left, s.left, 32), 80);
}

TEST_F(CanEncoder, SixtyFourBitCountsWrapWithoutOverflow) {
  // Regression (fuzz_canenc, first seconds): with 64-bit counts the step last - first was
  // computed in signed 64-bit arithmetic and overflowed (UBSan). Left: INT64_MAX - 9 then
  // INT64_MIN + 10: modulo 2^64 the step is +20 counts. Right, reversed: INT64_MIN (its
  // negation is itself modulo 2^64) then INT64_MIN + 5, negated: INT64_MAX - 4, a step of -5.
  cfg.left = CanCountLayout{0x100, false, 0, 64, true, false};
  cfg.right = CanCountLayout{0x101, false, 0, 64, true, false};
  cfg.reverse_right = true;
  CanEncoderSource enc = make();
  EXPECT_EQ(enc.counter_bits(), 64);
  auto le64 = [](std::uint32_t id, std::uint64_t v, TimeNs t) {
    CanFrame f = frame(id, {0, 0, 0, 0, 0, 0, 0, 0}, t);
    for (std::size_t i = 0; i < 8; ++i) f.data[i] = static_cast<std::uint8_t>(v >> (8 * i));
    return f;
  };
  port.inject(le64(0x100, 0x7FFFFFFFFFFFFFF6ull, 10 * kMs));
  port.inject(le64(0x101, 0x8000000000000000ull, 10 * kMs));
  const EncoderSample a = enc.read(10 * kMs);
  EXPECT_EQ(a.left, INT64_MAX - 9);
  EXPECT_EQ(a.right, INT64_MIN);
  port.inject(le64(0x100, 0x800000000000000Aull, 20 * kMs));
  port.inject(le64(0x101, 0x8000000000000005ull, 20 * kMs));
  const EncoderSample s = enc.read(20 * kMs);
  EXPECT_EQ(s.flags, 0u);
  EXPECT_EQ(s.left, INT64_MIN + 10);
  EXPECT_EQ(s.right, INT64_MAX - 4);
  EXPECT_EQ(wrap_delta(a.left, s.left, 64), 20);
  EXPECT_EQ(wrap_delta(a.right, s.right, 64), -5);
}

TEST_F(CanEncoder, ReverseNegatesTheCount) {
  cfg.reverse_right = true;
  CanEncoderSource enc = make();
  port.inject(odrive(0, 10, 10 * kMs));
  port.inject(odrive(1, 10, 10 * kMs));
  const EncoderSample a = enc.read(10 * kMs);
  EXPECT_EQ(a.left, 10);
  EXPECT_EQ(a.right, -10);
  port.inject(odrive(0, 30, 20 * kMs));
  port.inject(odrive(1, 30, 20 * kMs));
  const EncoderSample s = enc.read(20 * kMs);
  EXPECT_EQ(s.left, 30);    // +20
  EXPECT_EQ(s.right, -30);  // -20
}

TEST_F(CanEncoder, FloodBeyondTheCapIsReadOverTheNextTicksAndOnlyTheNewestCountMatters) {
  cfg.max_frames_per_read = 64;
  CanEncoderSource enc = make();
  // 300 frames: foreign ids interleaved with our counts 1..100 of each wheel, all at 5 ms.
  int ours = 0;
  for (int k = 1; k <= 100; ++k) {
    port.inject(frame(0x100 + static_cast<std::uint32_t>(k), {1, 2, 3, 4, 5, 6, 7, 8}, 5 * kMs));
    port.inject(odrive(0, k, 5 * kMs));
    port.inject(odrive(1, 2 * k, 5 * kMs));
    ours += 2;
  }
  ASSERT_EQ(ours, 200);
  // 300 frames at 64 per read: reads 1-4 take 64 each (256), read 5 the remaining 44.
  EncoderSample s;
  for (int r = 1; r <= 5; ++r) s = enc.read(5 * kMs + r * kMs);
  EXPECT_EQ(enc.stats().frames, 300u);
  EXPECT_EQ(enc.stats().foreign, 100u);
  EXPECT_EQ(enc.stats().decoded, 200u);
  EXPECT_EQ(enc.stats().capped_reads, 4u);
  // Frame 3(k-1)+1 is foreign k, 3(k-1)+2 left k (count k), 3k right k (count 2k). Read 1
  // takes frames 1..64 (up to foreign 22): its newest counts are left 21 and right 42. The
  // newest at the end are left 100 and right 200 (the counts as sent). All frames carry the
  // stamp 5 ms, so the limit per read is
  // 10 000 * (0 + 0.005 s slack) + 1 = 51 counts; the largest step per read is the right
  // wheel's 84 -> 128 = 44 (read 3 ends at frame 192 = right 64): no jump is flagged.
  EXPECT_EQ(s.left, 100);
  EXPECT_EQ(s.right, 200);
  EXPECT_EQ(s.flags, 0u);
  EXPECT_EQ(s.counters.implausible_jumps, 0u);
}

TEST_F(CanEncoder, ShortFramesAndRemoteRequestsWithOurIdAreIgnored) {
  CanEncoderSource enc = make();
  port.inject(odrive(0, 7, 1 * kMs));
  port.inject(odrive(1, 7, 1 * kMs));
  enc.read(1 * kMs);
  port.inject(frame(0x00A, {9, 9}, 2 * kMs));  // DLC 2
  CanFrame rtr = frame(0x02A, {}, 2 * kMs);
  rtr.rtr = true;
  rtr.len = 8;
  port.inject(rtr);
  const EncoderSample s = enc.read(3 * kMs);
  EXPECT_EQ(s.left, 7);  // unchanged since the count frames
  EXPECT_EQ(s.right, 7);
  EXPECT_EQ(enc.stats().short_frames, 1u);
  EXPECT_EQ(enc.stats().remote, 1u);
}

TEST_F(CanEncoder, BothWheelsInOneFrame) {
  // A two-axis controller: one frame, id 0x18FF0010 (29-bit), left int32 big endian at
  // byte 0, right at byte 4.
  cfg.left = CanCountLayout{0x18FF0010, true, 0, 32, true, true};
  cfg.right = CanCountLayout{0x18FF0010, true, 4, 32, true, true};
  CanEncoderSource enc = make();
  port.inject(frame(0x18FF0010, {0, 0, 0, 0, 0, 0, 0, 0}, 1 * kMs, true));
  enc.read(1 * kMs);
  // left 0x00000040 = 64, right 0xFFFFFFC0 = -64.
  port.inject(frame(0x18FF0010, {0, 0, 0, 0x40, 0xFF, 0xFF, 0xFF, 0xC0}, 11 * kMs, true));
  const EncoderSample s = enc.read(11 * kMs);
  EXPECT_EQ(s.flags, 0u);
  EXPECT_EQ(s.left, 64);
  EXPECT_EQ(s.right, -64);
}

TEST_F(CanEncoder, RemoteRequestsAtTheConfiguredPeriodNeverBlock) {
  cfg.request_period = 20 * kMs;
  CanEncoderSource enc = make();  // the port's transmit queue holds 8 frames
  // Reads every 10 ms from 0 to 90 ms: requests at 0, 20, 40, 60, 80 ms, two frames each.
  for (TimeNs t = 0; t < 100 * kMs; t += 10 * kMs) enc.read(t);
  // 10 requests for 8 places: 8 sent, 2 refused (queue full) and counted, none waited for.
  EXPECT_EQ(enc.stats().requests_sent, 8u);
  EXPECT_EQ(enc.stats().requests_dropped, 2u);
  CanFrame f;
  ASSERT_TRUE(port.drain_tx(f));
  EXPECT_TRUE(f.rtr);
  EXPECT_EQ(f.id, 0x00Au);
  EXPECT_EQ(f.len, 8);
  ASSERT_TRUE(port.drain_tx(f));
  EXPECT_EQ(f.id, 0x02Au);
}

TEST_F(CanEncoder, CreateRejectsMismatchedWidthsAndOverlaps) {
  cfg.right.width_bits = 16;
  EXPECT_FALSE(CanEncoderSource::create(port, cfg).ok());
  cfg.right = cfg.left;
  EXPECT_NE(CanEncoderSource::create(port, cfg).error().message.find("same bytes"),
            std::string::npos);
  cfg.right = odrive_count_layout(1);
  cfg.max_frames_per_read = 0;
  EXPECT_FALSE(CanEncoderSource::create(port, cfg).ok());
}

// Two wheels per side (issue 38): ODrive nodes 0 and 2 on the left, 1 and 3 on the right.
struct CanEncoderTwoPerSide : CanEncoder {
  CanEncoderTwoPerSide() {
    cfg.wheels.wheels_per_side = 2;
    cfg.more_left[0] = odrive_count_layout(2);   // id 0x04A
    cfg.more_right[0] = odrive_count_layout(3);  // id 0x06A
  }
};

// Each side is the mean of its wheels' travel; each wheel's counter wraps on its own.
TEST_F(CanEncoderTwoPerSide, SidesAreTheMeanOfTheirWheelsEachWrappingOnItsOwn) {
  CanEncoderSource enc = make();
  EXPECT_EQ(enc.counter_bits(), 64);  // the combined counts never wrap
  // Before any frame: both sides stale at 0, and no wheel counted as dropped.
  EncoderSample s = enc.read(1 * kMs);
  EXPECT_EQ(s.flags, kEncoderStaleLeft | kEncoderStaleRight);
  EXPECT_EQ(s.left, 0);
  EXPECT_EQ(s.counters.wheel_drops, 0u);
  // First frames: every wheel takes its reference, the sides start at 0. Left wheel 2 sits 47
  // counts below the int32 maximum 2147483647.
  port.inject(odrive(0, 1000, 5 * kMs));
  port.inject(odrive(2, 2147483600, 5 * kMs));
  port.inject(odrive(1, 50, 5 * kMs));
  port.inject(odrive(3, 70, 5 * kMs));
  s = enc.read(6 * kMs);
  EXPECT_EQ(s.flags, 0u);
  EXPECT_EQ(s.left, 0);
  EXPECT_EQ(s.right, 0);
  EXPECT_EQ(s.stamp, 5 * kMs);
  // 10 ms later: left +40 and +50 (wheel 2 wraps: 2147483600 + 50 - 2^32 = -2147483646),
  // right -30 and -34 (all under the 150-count jump limit: 10 000 counts/s * (10 + 5) ms).
  // Means: left (40 + 50) / 2 = 45, right (-30 - 34) / 2 = -32.
  port.inject(odrive(0, 1040, 15 * kMs));
  port.inject(odrive(2, -2147483646, 15 * kMs));
  port.inject(odrive(1, 20, 15 * kMs));
  port.inject(odrive(3, 36, 15 * kMs));
  s = enc.read(16 * kMs);
  EXPECT_EQ(s.flags, 0u);
  EXPECT_EQ(s.left, 45);
  EXPECT_EQ(s.right, -32);
  EXPECT_EQ(s.counters.wheel_drops, 0u);
}

// A wheel whose controller falls silent is dropped from its side once stale (flagged
// wheel-dropped, not stale: its neighbour carries the side); it rejoins from its next frame
// without its silent motion; a side whose wheels are all silent is stale.
TEST_F(CanEncoderTwoPerSide, SilentWheelIsDroppedWhileTheOtherCarriesTheSide) {
  CanEncoderSource enc = make();
  // Every 10 ms from 10 ms: left wheels +20 counts per 10 ms, right wheels +10; left wheel 2
  // (node 2) sends only at 10 ms until it comes back at 110 ms.
  auto send = [&](TimeNs t, bool left2) {
    const auto ms = static_cast<std::int32_t>(t / kMs) - 10;
    port.inject(odrive(0, 2 * ms, t));
    if (left2) port.inject(odrive(2, 2 * ms, t));
    port.inject(odrive(1, ms, t));
    port.inject(odrive(3, ms, t));
  };
  EncoderSample s;
  for (TimeNs t = 10 * kMs; t <= 100 * kMs; t += 10 * kMs) {
    send(t, t == 10 * kMs);
    s = enc.read(t);
    if (t <= 60 * kMs) {
      // Node 2's newest frame (10 ms) is 50 ms old or less: fresh, and it holds the instant
      // back at 10 ms, where every wheel's count is its first: both sides 0.
      EXPECT_EQ(s.flags, 0u) << t;
      EXPECT_EQ(s.stamp, 10 * kMs) << t;
      EXPECT_EQ(s.left, 0) << t;
    } else {
      // Stale from 70 ms (60 ms > 50 ms): dropped; the left side is node 0 alone, at the read's
      // frames: 2 * (t - 10 ms) counts; the right side (t - 10 ms).
      EXPECT_EQ(s.flags, kEncoderWheelDropped) << t;
      EXPECT_EQ(s.stamp, t) << t;
      EXPECT_EQ(s.left, 2 * (t / kMs - 10)) << t;
      EXPECT_EQ(s.right, t / kMs - 10) << t;
    }
  }
  EXPECT_EQ(s.counters.wheel_drops, 1u);
  EXPECT_EQ(s.counters.stale_events, 0u);  // the side never went stale
  // Node 2 returns at 110 ms at 200 counts (its motion while silent): it takes that as its new
  // reference; the left side is node 0's 200. From 120 ms both wheels count: +20 each, 220.
  send(110 * kMs, true);
  s = enc.read(110 * kMs);
  EXPECT_EQ(s.flags, 0u);
  EXPECT_EQ(s.left, 200);
  send(120 * kMs, true);
  s = enc.read(120 * kMs);
  EXPECT_EQ(s.flags, 0u);
  EXPECT_EQ(s.left, 220);
  // Both left controllers silent, the right ones sending: from 180 ms (60 ms > 50 ms) the left
  // side is stale and keeps 220; one side event, two more wheel drops.
  for (TimeNs t = 130 * kMs; t <= 200 * kMs; t += 10 * kMs) {
    port.inject(odrive(1, static_cast<std::int32_t>(t / kMs) - 10, t));
    port.inject(odrive(3, static_cast<std::int32_t>(t / kMs) - 10, t));
    s = enc.read(t);
  }
  EXPECT_EQ(s.flags & (kEncoderStaleLeft | kEncoderStaleRight), kEncoderStaleLeft);
  EXPECT_EQ(s.left, 220);
  EXPECT_EQ(s.right, 190);
  EXPECT_EQ(s.counters.stale_events, 1u);
  EXPECT_EQ(s.counters.wheel_drops, 3u);
}

TEST_F(CanEncoderTwoPerSide, CreateNamesTheWheelsThatOverlapAndTheWheelCount) {
  cfg.more_left[0] = cfg.left;
  auto e = CanEncoderSource::create(port, cfg);
  ASSERT_FALSE(e.ok());
  EXPECT_EQ(e.error().message,
            "left wheel 1 and left wheel 2 read the same bytes of the same frame");
  cfg.more_left[0] = odrive_count_layout(2);
  cfg.more_right[0].width_bits = 16;
  e = CanEncoderSource::create(port, cfg);
  ASSERT_FALSE(e.ok());
  EXPECT_EQ(e.error().message, "all wheels' counts must have the same width");
  cfg.wheels.wheels_per_side = 5;
  e = CanEncoderSource::create(port, cfg);
  ASSERT_FALSE(e.ok());
  EXPECT_EQ(e.error().message, "wheels_per_side 5 must be 1..4");
}

TEST(SimOdrive, PublishesCanSimpleEncoderCountFrames) {
  sim::SimCanPort port(8, 8);
  sim::SimOdrive od(port, sim::SimOdriveOptions{2, 5, 8192});
  // Left: -3 counts: shadow 0xFFFFFFFD, count in CPR (-3 mod 8192) = 8189 = 0x1FFD.
  // Right: 2^32 + 7 counts: the shadow count keeps the low 32 bits = 7; in CPR 7.
  od.publish(42, -3, (std::int64_t{1} << 32) + 7);
  CanFrame f;
  ASSERT_TRUE(port.receive(f));
  EXPECT_EQ(f.id, (2u << 5) | 0x00Au);  // 0x04A
  EXPECT_EQ(f.len, 8);
  EXPECT_EQ(f.stamp, 42);
  const std::array<std::uint8_t, 8> left{0xFD, 0xFF, 0xFF, 0xFF, 0xFD, 0x1F, 0x00, 0x00};
  EXPECT_EQ(f.data, left);
  ASSERT_TRUE(port.receive(f));
  EXPECT_EQ(f.id, (5u << 5) | 0x00Au);  // 0x0AA
  const std::array<std::uint8_t, 8> right{7, 0, 0, 0, 7, 0, 0, 0};
  EXPECT_EQ(f.data, right);
  EXPECT_FALSE(port.receive(f));
  EXPECT_EQ(od.frames(), 2u);
}

TEST(SimOdrive, FaultHooksReachTheDriverAsStaleAndJump) {
  sim::SimCanPort port(8, 64);
  sim::SimOdrive od(port, sim::SimOdriveOptions{0, 1, 8192});
  CanEncoderConfig c;
  c.left = odrive_count_layout(0);
  c.right = odrive_count_layout(1);
  c.timeout = 50 * kMs;
  c.max_counts_per_s = 10'000;
  CanEncoderSource enc = CanEncoderSource::create(port, c).value();
  // Both axes at rest at 0, published every 10 ms.
  TimeNs t = 0;
  for (; t <= 30 * kMs; t += 10 * kMs) {
    od.publish(t, 0, 0);
    EXPECT_EQ(enc.read(t).flags, 0u);
  }
  // The right axis stops sending after 30 ms; the left leaps 1000 counts at 40 ms (limit
  // 10 000 * (0.010 + 0.005) + 1 = 151 counts).
  od.set_sending(1, false);
  od.add_jump(0, 1000);
  od.publish(t, 0, 0);
  EncoderSample s = enc.read(t);  // t = 40 ms
  EXPECT_EQ(s.flags, static_cast<std::uint32_t>(kEncoderImplausibleJump));
  EXPECT_EQ(s.left, 0);
  // The right wheel's last frame was at 30 ms: stale once the read is later than 80 ms.
  for (t += 10 * kMs; t <= 90 * kMs; t += 10 * kMs) {
    od.publish(t, 0, 0);
    s = enc.read(t);
    EXPECT_EQ(s.flags, t > 80 * kMs ? kEncoderStaleRight : 0u) << t;
  }
  EXPECT_EQ(s.counters.stale_events, 1u);
  EXPECT_EQ(s.counters.implausible_jumps, 1u);
}

}  // namespace
}  // namespace odo::drivers
