// SerialCountsSource (issue 37) over an in-memory ByteLink: both protocols, and every fault the
// issue lists: garbage, CRC errors, sequence gaps, a controller reset, a link that vanishes and
// comes back, a board that never answers, a wrong baud rate (bytes but nothing valid).
#include <gtest/gtest.h>

#include <array>
#include <deque>
#include <string>

#include "odo/protocol/serial_counts.hpp"
#include "odo/protocol/serial_counts_source.hpp"

namespace odo::protocol {
namespace {

constexpr TimeNs kMs = 1'000'000;

struct FakeLink final : ByteLink {
  std::deque<std::uint8_t> in;
  std::string written;
  bool gone = false;
  bool can_reopen = true;
  int reopens = 0;
  int read(std::span<std::uint8_t> out, TimeNs& /*arrival*/) noexcept override {
    if (gone) return -1;
    std::size_t n = 0;
    for (; n < out.size() && !in.empty(); ++n) {
      out[n] = in.front();
      in.pop_front();
    }
    return static_cast<int>(n);
  }
  bool write(std::span<const std::uint8_t> d) noexcept override {
    written.append(d.begin(), d.end());
    return !gone;
  }
  bool reopen() noexcept override {
    ++reopens;
    if (can_reopen) gone = false;
    return can_reopen;
  }
  void send(const SerialCounts& c) {
    std::array<std::uint8_t, kSerialCountsFrameMax> f{};
    const std::size_t n = encode_serial_counts(c, f);
    in.insert(in.end(), f.begin(), f.begin() + static_cast<std::ptrdiff_t>(n));
  }
  void send(const std::string& s) { in.insert(in.end(), s.begin(), s.end()); }
  void send_v2(const SerialCounts& c) {
    std::array<std::uint8_t, kSerialCountsFrameMaxV2> f{};
    const std::size_t n = encode_serial_counts_v2(c, f);
    in.insert(in.end(), f.begin(), f.begin() + static_cast<std::ptrdiff_t>(n));
  }
};

SerialSourceConfig stream_config() {
  SerialSourceConfig c;
  c.protocol = SerialProtocol::kDiffodom;
  c.max_counts_per_s = 1e5;  // 1000 counts per 10 ms
  return c;
}

SerialCounts rec(std::uint16_t seq, std::uint32_t time_us, std::int32_t l, std::int32_t r,
                 std::uint8_t flags = 0) {
  return SerialCounts{.seq = seq, .time_us = time_us, .left = l, .right = r, .flags = flags};
}

TEST(SerialSourceStream, CountsAndFaults) {
  FakeLink link;
  SerialCountsSource src(link, stream_config());
  // Before any record: both wheels stale, counts 0.
  EncoderSample s = src.read(0);
  EXPECT_EQ(s.flags & (kEncoderStaleLeft | kEncoderStaleRight),
            kEncoderStaleLeft | kEncoderStaleRight);
  // A first record (the board was counting already: 1000 / -500): the counts start there.
  link.send(rec(7, 1'000'000, 1000, -500));
  s = src.read(10 * kMs);
  EXPECT_EQ(s.flags, 0u);
  EXPECT_EQ(s.left, 1000);
  EXPECT_EQ(s.right, -500);
  // Next record +10 / +20 counts.
  link.send(rec(8, 1'010'000, 1010, -480));
  s = src.read(20 * kMs);
  EXPECT_EQ(s.left, 1010);
  EXPECT_EQ(s.right, -480);
  // Garbage (zeros end two bogus frames), then a record with a CRC error (a counter byte
  // changed on the wire), then seq 11 (9 and 10 lost: one gap, two records lost).
  link.send(std::string("\x13\x37\x00\x55\x00", 5));
  std::array<std::uint8_t, kSerialCountsFrameMax> f{};
  encode_serial_counts(rec(9, 1'020'000, 1020, -470), f);
  f[10] ^= 0x01;  // a byte of the left counter
  ASSERT_NE(f[10], 0);
  link.in.insert(link.in.end(), f.begin(), f.end());
  link.send(rec(11, 1'040'000, 1040, -450));
  s = src.read(40 * kMs);
  EXPECT_NE(s.flags & kEncoderLinkError, 0u);
  EXPECT_EQ(s.counters.link_errors, 3u);  // two garbage frames, one CRC mismatch
  EXPECT_EQ(src.stats().crc_errors, 1u);
  EXPECT_EQ(s.counters.sequence_gaps, 1u);
  EXPECT_EQ(src.stats().lost_records, 2u);
  EXPECT_EQ(s.left, 1040);  // cumulative counts: nothing of the motion is lost
  EXPECT_EQ(s.right, -450);
  // The controller resets: seq 0, its clock from 0, booted flag, counters since boot 3 / 4.
  link.send(rec(0, 2000, 3, 4, kSerialFlagBooted));
  s = src.read(50 * kMs);
  EXPECT_NE(s.flags & kEncoderControllerReset, 0u);
  EXPECT_EQ(s.counters.controller_resets, 1u);
  EXPECT_EQ(s.counters.sequence_gaps, 1u);  // a reset is not a gap
  EXPECT_EQ(s.counters.implausible_jumps, 0u);
  EXPECT_EQ(s.left, 1043);  // the 3 / 4 counts since the boot are motion: no jump, no spin
  EXPECT_EQ(s.right, -446);
  // Still booted-flagged records afterwards are no further resets.
  link.send(rec(1, 12000, 5, 6, kSerialFlagBooted));
  s = src.read(60 * kMs);
  EXPECT_EQ(s.counters.controller_resets, 1u);
  EXPECT_EQ(s.left, 1045);
  // Nothing for longer than the 100 ms timeout: stale, one stale event.
  s = src.read(200 * kMs);
  EXPECT_EQ(s.flags & kEncoderStaleLeft, kEncoderStaleLeft);
  EXPECT_EQ(s.counters.stale_events, 1u);
}

TEST(SerialSourceStream, FirstRecordOfABootedControllerIsAReset) {
  // odometryd (re)starts right after the controller booted: the first sample says so, for the
  // resume decision (controller-reset: a fresh start, never the old record's counts continued).
  FakeLink link;
  SerialCountsSource src(link, stream_config());
  link.send(rec(0, 1000, 2, 3, kSerialFlagBooted));
  const EncoderSample s = src.read(10 * kMs);
  EXPECT_EQ(s.flags, static_cast<std::uint32_t>(kEncoderControllerReset));
  EXPECT_EQ(s.counters.controller_resets, 1u);
  EXPECT_EQ(s.left, 2);
  EXPECT_EQ(s.right, 3);
}

TEST(SerialSourceStream, UnplugReopenAndWrongBaud) {
  FakeLink link;
  SerialSourceConfig c = stream_config();
  c.reopen_period = 100 * kMs;
  SerialCountsSource src(link, c);
  link.send(rec(0, 0, 10, 10));
  EXPECT_EQ(src.read(10 * kMs).left, 10);
  // Unplugged: a read error (the loop skips the sample), no reopen before 100 ms.
  link.gone = true;
  link.can_reopen = false;
  EncoderSample s = src.read(20 * kMs);
  EXPECT_NE(s.flags & kEncoderReadError, 0u);
  EXPECT_EQ(s.counters.read_errors, 1u);
  src.read(60 * kMs);
  EXPECT_EQ(link.reopens, 0);
  src.read(130 * kMs);  // due: fails (not back yet)
  EXPECT_EQ(link.reopens, 1);
  EXPECT_EQ(src.stats().open_failures, 1u);
  // Back (maybe under another name: the link reopens its path): half a frame first (joined
  // mid-frame: not counted), then records carry on.
  link.can_reopen = true;
  link.send(std::string("\x44\x55\x00", 3));
  link.send(rec(30, 300'000, 40, 50));
  s = src.read(240 * kMs);
  EXPECT_EQ(s.counters.reconnects, 1u);
  EXPECT_EQ(s.counters.link_errors, 0u);
  EXPECT_EQ(s.left, 40);
  EXPECT_EQ(s.right, 50);
  // A wrong baud rate: bytes arrive, none forms a frame (here: a reopened line of 0x80s and
  // zeros, as 8N1 bytes sent at a quarter of the rate look): flagged no-valid-data.
  link.gone = true;
  src.read(250 * kMs);
  for (int i = 0; i < 80; ++i) link.send(std::string(i % 5 == 4 ? "\x00" : "\x80", 1));
  s = src.read(400 * kMs);
  EXPECT_NE(s.flags & kEncoderNoValidData, 0u);
  EXPECT_GT(s.counters.link_errors, 0u);
  EXPECT_EQ(s.left, 40);  // nothing integrated from garbage
}

SerialSourceConfig bridge_config() {
  SerialSourceConfig c;
  c.protocol = SerialProtocol::kArduinoBridge;
  c.poll_period = 10 * kMs;
  c.max_counts_per_s = 1e5;
  c.bits_left = c.bits_right = 16;  // an Arduino sketch with int counters
  return c;
}

TEST(SerialSourceBridge, PollsAnswersAndFaults) {
  FakeLink link;
  SerialCountsSource src(link, bridge_config());
  src.read(0);
  EXPECT_EQ(link.written, "e\r");  // ros_arduino_bridge's read-encoders command
  link.send("12 -34\r\n");
  EncoderSample s = src.read(10 * kMs);
  EXPECT_EQ(s.left, 12);
  EXPECT_EQ(s.right, -34);
  // Requested at 0, answer seen at 10 ms: stamped at the midpoint, 5 ms.
  EXPECT_EQ(s.stamp, 5 * kMs);
  EXPECT_EQ(link.written, "e\re\r");
  // 788 counts in 10 ms: within the jump limit.
  link.send("800 -34\r\n");
  s = src.read(20 * kMs);
  EXPECT_EQ(s.left, 800);
  EXPECT_EQ(s.stamp, 15 * kMs);
  // A garbage line and an over-long line: link errors; the answer after them counts.
  link.send("x1 2\r\n");
  std::string over_long(100, '7');
  over_long += "\r\n";  // two steps: see TESTING.md, "The tests' precompiled header"
  link.send(over_long);
  link.send("900 -30\r\n");
  s = src.read(30 * kMs);
  EXPECT_EQ(s.counters.link_errors, 2u);
  EXPECT_EQ(s.left, 900);
  // The board never answers: after the 100 ms timeout the request is given up and the wheels
  // are stale; requests go on.
  for (TimeNs t = 40; t <= 200; t += 10) s = src.read(t * kMs);
  EXPECT_GT(src.stats().unanswered, 0u);
  EXPECT_EQ(s.flags & kEncoderStaleLeft, kEncoderStaleLeft);
  // The board restarted (both counters at exactly 0), then moved 5 / 6: counts continue.
  link.send("0 0\r\n");
  s = src.read(210 * kMs);
  EXPECT_EQ(s.counters.controller_resets, 1u);
  EXPECT_EQ(s.left, 900);
  EXPECT_EQ(s.right, -30);
  // "OK" (the answer to "r") is no error.
  link.send("OK\r\n5 6\r\n");
  s = src.read(220 * kMs);
  EXPECT_EQ(s.counters.link_errors, 2u);
  EXPECT_EQ(s.left, 905);
  EXPECT_EQ(s.right, -24);
}

TEST(SerialSourceBridge, SixteenBitWrap) {
  FakeLink link;
  SerialCountsSource src(link, bridge_config());
  src.read(0);
  link.send("32760 0\r\n");
  EXPECT_EQ(src.read(10 * kMs).left, 32760);
  // An int16 counter on the board wraps from 32767 to -32768: 32760 -> -32766 is +10 counts.
  link.send("-32766 0\r\n");
  EXPECT_EQ(src.read(20 * kMs).left, 32770);
}

// Two wheels per side (issue 38): version 2 records; each side the mean of its wheels' steps; a
// wheel the board flags, or whose step is implausible, dropped for that read and re-referenced
// after; a record of another wheel count is a link error.
TEST(SerialSourceWheels, TwoPerSideMeanBoardFaultJumpAndWrongWheelCount) {
  FakeLink link;
  SerialSourceConfig cfg = stream_config();
  cfg.wheels.wheels_per_side = 2;
  SerialCountsSource src(link, cfg);
  EXPECT_EQ(src.counter_bits(), 64);
  auto v2 = [](std::uint16_t seq, std::int32_t l1, std::int32_t l2, std::int32_t r1,
               std::int32_t r2, std::uint8_t faults = 0) {
    SerialCounts c = rec(seq, 10'000u * seq, l1, r1);
    c.wheels_per_side = 2;
    c.more_left[0] = l2;
    c.more_right[0] = r2;
    c.wheel_faults = faults;
    return c;
  };
  // Before any record: both sides stale at 0, no wheel drop counted.
  EncoderSample s = src.read(0);
  EXPECT_EQ(s.flags, kEncoderStaleLeft | kEncoderStaleRight);
  EXPECT_EQ(s.counters.wheel_drops, 0u);
  // The first record is every wheel's reference: the sides start at 0.
  link.send_v2(v2(0, 100, 200, 10, 20));
  s = src.read(1 * kMs);
  EXPECT_EQ(s.flags, 0u);
  EXPECT_EQ(s.left, 0);
  EXPECT_EQ(s.right, 0);
  // Left +40 and +60: 50; right -10 and +10: 0.
  link.send_v2(v2(1, 140, 260, 0, 30));
  s = src.read(11 * kMs);
  EXPECT_EQ(s.flags, 0u);
  EXPECT_EQ(s.left, 50);
  EXPECT_EQ(s.right, 0);
  // The board flags left wheel 2 (bit 1): its garbage count is dropped, wheel 1's +40 is the
  // side's: 90.
  link.send_v2(v2(2, 180, 999'999, 0, 30, 0x02));
  s = src.read(21 * kMs);
  EXPECT_EQ(s.flags, kEncoderWheelDropped);
  EXPECT_EQ(s.left, 90);
  EXPECT_EQ(s.counters.wheel_drops, 1u);
  // Clean again: wheel 2 takes 1 000 100 as its new reference (rejoins next read): 90 + 40.
  link.send_v2(v2(3, 220, 1'000'100, 0, 30));
  s = src.read(31 * kMs);
  EXPECT_EQ(s.flags, 0u);
  EXPECT_EQ(s.left, 130);
  // Both count: +40 and +50: 45 -> 175.
  link.send_v2(v2(4, 260, 1'000'150, 0, 30));
  s = src.read(41 * kMs);
  EXPECT_EQ(s.left, 175);
  // Left wheel 1 jumps +5000 (limit 1e5 counts/s * (10 + 20) ms + 1 = 3001): flagged, counted,
  // dropped; wheel 2's +50 carries the side: 225.
  link.send_v2(v2(5, 5260, 1'000'200, 0, 30));
  s = src.read(51 * kMs);
  EXPECT_EQ(s.flags, kEncoderImplausibleJump | kEncoderWheelDropped);
  EXPECT_EQ(s.left, 225);
  EXPECT_EQ(s.counters.implausible_jumps, 1u);
  EXPECT_EQ(s.counters.wheel_drops, 2u);
  // A version 1 record (one wheel per side) from a board that is not this robot's: a link error,
  // the counts hold.
  link.send(rec(6, 60'000, 1, 1));
  s = src.read(61 * kMs);
  EXPECT_EQ(s.flags & kEncoderLinkError, kEncoderLinkError);
  EXPECT_EQ(s.left, 225);
  EXPECT_EQ(s.counters.link_errors, 1u);
}

}  // namespace
}  // namespace odo::protocol
