// CAN gyro (issue 16, CAN backend): CanGyroSource against sim_hal's SimCanPort. Frames are
// packed here by hand, byte by byte (not with the decoder), and the rates derived in comments.
// Scales are powers of two, so v * scale is exact in double and the expected rates are exact.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <initializer_list>
#include <limits>
#include <string>
#include <vector>

#include "can_frame_bytes.hpp"
#include "odo/drivers/can_gyro.hpp"
#include "odo/sim/sim_can_bus.hpp"

namespace odo::drivers {
namespace {

constexpr TimeNs kMs = 1'000'000;
constexpr std::uint32_t kId = 0x123;
// 2^-12 rad/s per LSB: a signed 16-bit field spans -8 .. +7.999755859375 rad/s (±458 deg/s).
const double kScale16 = std::ldexp(1.0, -12);

using test::frame;

// le16: a frame of kId whose first two bytes are `lo`, `hi` (a 16-bit field at offset 0, LE).
CanFrame le16(std::uint8_t lo, std::uint8_t hi, TimeNs stamp) {
  return frame(kId, {lo, hi}, stamp);
}

struct CanGyro : ::testing::Test {
  sim::SimCanPort port{8, 512};
  CanGyroConfig cfg = [] {
    CanGyroConfig c;
    c.field = CanCountLayout{kId, false, 0, 16, true, false};  // int16 LE at byte 0
    c.scale = std::ldexp(1.0, -12);
    c.stale_timeout = 50 * kMs;
    return c;
  }();
  CanGyroSource make() {
    auto s = CanGyroSource::create(port, cfg);
    EXPECT_TRUE(s.ok()) << (s.ok() ? "" : s.error().message);
    return std::move(s).value();
  }
  // rejected: the message create() gives for `c` ("" if it was accepted).
  std::string rejected(const CanGyroConfig& c) {
    auto s = CanGyroSource::create(port, c);
    return s.ok() ? std::string() : s.error().message;
  }
};

// Each bad field on its own is rejected, with a message that names it.
TEST_F(CanGyro, CreateRejectsEachBadFieldNamingIt) {
  EXPECT_EQ(rejected(cfg), "");
  auto expect_named = [&](const CanGyroConfig& c, const std::string& name) {
    const std::string m = rejected(c);
    EXPECT_NE(m.find("CAN gyro"), std::string::npos) << m;
    EXPECT_NE(m.find(name), std::string::npos) << "'" << m << "' does not name " << name;
  };
  for (int w : {8, 40, 64}) {
    CanGyroConfig c = cfg;
    c.field.width_bits = w;
    expect_named(c, "width " + std::to_string(w));
  }
  {
    CanGyroConfig c = cfg;  // 7 + 2 bytes = 9 > 8 data bytes
    c.field.byte_offset = 7;
    expect_named(c, "byte offset 7");
    c.field.byte_offset = 6;  // 6 + 2 = 8: the last two bytes
    EXPECT_EQ(rejected(c), "");
  }
  for (double s : {0.0, -kScale16, std::numeric_limits<double>::quiet_NaN()}) {
    CanGyroConfig c = cfg;
    c.scale = s;
    expect_named(c, "scale");
  }
  for (double off : {std::numeric_limits<double>::quiet_NaN(), 1e4}) {  // [rad/s]
    CanGyroConfig c = cfg;
    c.offset = off;
    expect_named(c, "offset must be");
  }
  for (int sign : {0, 2, -2}) {
    CanGyroConfig c = cfg;
    c.sign = sign;
    expect_named(c, "sign");
  }
  {
    CanGyroConfig c = cfg;
    c.stale_timeout = 0;
    expect_named(c, "stale_timeout");
  }
  for (int n : {0, 4097}) {
    CanGyroConfig c = cfg;
    c.max_frames_per_read = n;
    expect_named(c, "max_frames_per_read");
  }
  for (int n : {1, 4096}) {
    CanGyroConfig c = cfg;
    c.max_frames_per_read = n;
    EXPECT_EQ(rejected(c), "") << n;
  }
}

// An unsigned field spans 0 .. 65535 LSB: without an offset it reads 0 .. 65535 s rad/s and
// cannot say "at rest" without saturating; an offset of +1 or -70000 LSB moves the whole range
// off 0 too. Only an offset inside the field (here -32000 LSB) is accepted.
TEST_F(CanGyro, CreateRejectsAnUnsignedRangeWithoutZero) {
  CanGyroConfig c = cfg;
  c.field.is_signed = false;
  for (double off_lsb : {0.0, 1.0, -70000.0}) {
    c.offset = off_lsb * kScale16;
    const std::string m = rejected(c);
    EXPECT_NE(m.find("range"), std::string::npos) << off_lsb << ": " << m;
  }
  c.offset = -32000.0 * kScale16;
  EXPECT_EQ(rejected(c), "");
}

struct Case {
  int width;
  bool big_endian;
  int offset;
  CanFrame f;
  std::int64_t v;  // the field's value the bytes hold [LSB]
};

// Signed fields of every width and both byte orders (filler 0xAA around the field must not be
// read). The scale 2^-(width-4) keeps the rates in a gyro's range; v * scale is exact.
TEST_F(CanGyro, SignedFieldsOfEachWidthAndByteOrderDecodeToValueTimesScale) {
  const std::uint8_t A = 0xAA;
  const Case cases[] = {
      // -12345 = 65536 - 12345 = 53191 = 0xCFC7; LE at byte 0: C7 CF.
      {16, false, 0, frame(kId, {0xC7, 0xCF, A, A, A, A, A, A}, kMs), -12345},
      // 12345 = 0x3039; BE at byte 2: 30 39.
      {16, true, 2, frame(kId, {A, A, 0x30, 0x39, A, A, A, A}, kMs), 12345},
      // -1234567 = 2^24 - 1234567 = 15542649 = 0xED2979; LE at byte 1: 79 29 ED.
      {24, false, 1, frame(kId, {A, 0x79, 0x29, 0xED, A, A, A, A}, kMs), -1234567},
      // 1234567 = 0x12D687; BE at byte 5: 12 D6 87.
      {24, true, 5, frame(kId, {A, A, A, A, A, 0x12, 0xD6, 0x87}, kMs), 1234567},
      // -123456789 = 2^32 - 123456789 = 4171510507 = 0xF8A432EB; LE at byte 4: EB 32 A4 F8.
      {32, false, 4, frame(kId, {A, A, A, A, 0xEB, 0x32, 0xA4, 0xF8}, kMs), -123456789},
      // 123456789 = 0x075BCD15; BE at byte 0: 07 5B CD 15.
      {32, true, 0, frame(kId, {0x07, 0x5B, 0xCD, 0x15, A, A, A, A}, kMs), 123456789},
  };
  for (const Case& k : cases) {
    sim::SimCanPort p(8, 8);
    CanGyroConfig c = cfg;
    c.field = CanCountLayout{kId, false, k.offset, k.width, true, k.big_endian};
    c.scale = std::ldexp(1.0, -(k.width - 4));
    CanGyroSource g = CanGyroSource::create(p, c).value();
    ASSERT_TRUE(p.inject(k.f));
    const GyroSample s = g.read(2 * kMs);
    EXPECT_EQ(s.rate_z, static_cast<double>(k.v) * c.scale) << k.width << " bits";
    EXPECT_EQ(s.samples, 1u);
    EXPECT_EQ(s.flags, 0u) << k.width << " bits";
  }
  // The first case as a number: -12345 * 2^-12 = -3.013916015625 rad/s.
  EXPECT_EQ(-12345 * kScale16, -3.013916015625);
}

// J1939-style: unsigned 16-bit with an offset of -32000 LSB = -32000 / 4096 = -7.8125 rad/s.
TEST_F(CanGyro, UnsignedFieldWithNegativeOffset) {
  cfg.field.is_signed = false;
  cfg.field.id = 0x18FF0A10;
  cfg.field.extended = true;
  cfg.offset = -32000.0 * kScale16;
  CanGyroSource g = make();
  // Ends: 0 LSB -> -7.8125 rad/s, 65535 LSB -> 33535 / 4096 = 8.187255859375 rad/s; the
  // smaller magnitude is the full scale.
  EXPECT_EQ(g.full_scale(), 7.8125);
  auto one = [&](std::uint8_t lo, std::uint8_t hi, TimeNs t) {
    port.inject(frame(0x18FF0A10, {lo, hi}, t, true));
    return g.read(t);
  };
  // 32000 = 0x7D00 (LE 00 7D): at rest, 0 rad/s.
  EXPECT_EQ(one(0x00, 0x7D, 1 * kMs).rate_z, 0.0);
  // 36096 = 0x8D00: (36096 - 32000) / 4096 = +1 rad/s.
  EXPECT_EQ(one(0x00, 0x8D, 2 * kMs).rate_z, 1.0);
  // 29952 = 0x7500: (29952 - 32000) / 4096 = -0.5 rad/s.
  const GyroSample s = one(0x00, 0x75, 3 * kMs);
  EXPECT_EQ(s.rate_z, -0.5);
  EXPECT_EQ(s.flags, 0u);
}

TEST_F(CanGyro, SignMinusOneNegates) {
  cfg.sign = -1;
  CanGyroSource g = make();
  // 4096 = 0x1000 (LE 00 10): +1 rad/s on the device's axis, -1 rad/s about the robot's z.
  port.inject(le16(0x00, 0x10, 1 * kMs));
  EXPECT_EQ(g.read(1 * kMs).rate_z, -1.0);
  // -2048 = 0xF800 (LE 00 F8): -0.5 rad/s on the device, +0.5 rad/s.
  port.inject(le16(0x00, 0xF8, 2 * kMs));
  EXPECT_EQ(g.read(2 * kMs).rate_z, 0.5);
}

TEST_F(CanGyro, MeanOfTheFramesOfOneReadAndTheNewestStamp) {
  CanGyroSource g = make();
  // 1024, 2048, 6144 LSB (LE 00 04, 00 08, 00 18) = 0.25, 0.5, 1.5 rad/s at 11, 12, 13 ms:
  // mean (0.25 + 0.5 + 1.5) / 3 = 2.25 / 3 = 0.75 rad/s, stamp 13 ms.
  port.inject(le16(0x00, 0x04, 11 * kMs));
  port.inject(le16(0x00, 0x08, 12 * kMs));
  port.inject(le16(0x00, 0x18, 13 * kMs));
  GyroSample s = g.read(15 * kMs);
  EXPECT_EQ(s.rate_z, 0.75);
  EXPECT_EQ(s.samples, 3u);
  EXPECT_EQ(s.counters.samples, 3u);
  EXPECT_EQ(s.stamp, 13 * kMs);
  EXPECT_EQ(s.flags, 0u);
  // No frame since: the previous rate and stamp, 0 samples, still fresh (20 - 13 <= 50 ms).
  s = g.read(20 * kMs);
  EXPECT_EQ(s.rate_z, 0.75);
  EXPECT_EQ(s.samples, 0u);
  EXPECT_EQ(s.counters.samples, 3u);
  EXPECT_EQ(s.stamp, 13 * kMs);
  EXPECT_EQ(s.flags, 0u);
  // A frame without a receive stamp (0) is stamped with the read's `now`: 30 ms.
  // -4096 = 0xF000 (LE 00 F0): -1 rad/s.
  port.inject(le16(0x00, 0xF0, 0));
  s = g.read(30 * kMs);
  EXPECT_EQ(s.rate_z, -1.0);
  EXPECT_EQ(s.stamp, 30 * kMs);
  EXPECT_EQ(s.counters.samples, 4u);
}

// Before the first frame: starting (not usable, no event) for stale_timeout from the first read
// (also when the clock starts at 0, as the virtual clock does), then stale with one event; then
// one event per fresh -> stale transition.
TEST_F(CanGyro, StartingThenStaleBeforeTheFirstFrameThenOneEventPerTransition) {
  CanGyroSource g = make();
  // First read at 0: starting until 0 + 50 ms, stale (the first event) from 50 ms + 1 ns.
  for (TimeNs t : {TimeNs{0}, 10 * kMs, 50 * kMs}) {
    const GyroSample s = g.read(t);
    EXPECT_EQ(s.flags, static_cast<std::uint32_t>(kGyroStarting)) << t;
    EXPECT_EQ(s.counters.stale_events, 0u) << t;
    EXPECT_EQ(s.samples, 0u);
    EXPECT_EQ(s.rate_z, 0.0);
    EXPECT_EQ(s.stamp, 0);
  }
  for (TimeNs t : {50 * kMs + 1, 60 * kMs, 100 * kMs}) {
    const GyroSample s = g.read(t);
    EXPECT_EQ(s.flags, static_cast<std::uint32_t>(kGyroStale)) << t;
    EXPECT_EQ(s.counters.stale_events, 1u) << t;
    EXPECT_EQ(s.samples, 0u);
  }
  // First frame at 110 ms (2048 LSB = 0.5 rad/s): fresh while now - 110 ms <= 50 ms.
  port.inject(le16(0x00, 0x08, 110 * kMs));
  for (TimeNs t = 110 * kMs; t <= 160 * kMs; t += 10 * kMs) {
    const GyroSample s = g.read(t);
    EXPECT_EQ(s.flags, 0u) << t;
    EXPECT_EQ(s.rate_z, 0.5);
  }
  // 160 ms + 1 ns is 50 ms + 1 ns after the frame: stale, the second event; it stays two.
  for (TimeNs t : {160 * kMs + 1, 170 * kMs, 300 * kMs}) {
    const GyroSample s = g.read(t);
    EXPECT_EQ(s.flags, static_cast<std::uint32_t>(kGyroStale)) << t;
    EXPECT_EQ(s.counters.stale_events, 2u) << t;
    EXPECT_EQ(s.rate_z, 0.5);  // the last rate is kept
  }
  // Back at 400 ms, silent again: stale after 450 ms, the third event.
  port.inject(le16(0x00, 0x08, 400 * kMs));
  EXPECT_EQ(g.read(400 * kMs).flags, 0u);
  EXPECT_EQ(g.read(450 * kMs).flags, 0u);
  const GyroSample s = g.read(451 * kMs);
  EXPECT_EQ(s.flags, static_cast<std::uint32_t>(kGyroStale));
  EXPECT_EQ(s.counters.stale_events, 3u);
}

// int16: -32768 and 32767 are the field's ends (saturated), -32767 and 32766 are not.
TEST_F(CanGyro, SaturationAtBothEndsOfTheFieldOnly) {
  CanGyroSource g = make();
  struct End {
    std::uint8_t lo, hi;
    double rate;  // v / 4096
    bool saturated;
  };
  const End ends[] = {
      {0x00, 0x80, -8.0, true},                // -32768 = 0x8000
      {0x01, 0x80, -32767.0 / 4096.0, false},  // -32767 = 0x8001
      {0xFE, 0x7F, 32766.0 / 4096.0, false},   // 32766 = 0x7FFE
      {0xFF, 0x7F, 32767.0 / 4096.0, true},    // 32767 = 0x7FFF
  };
  std::uint64_t saturated = 0;
  TimeNs t = 0;
  for (const End& e : ends) {
    t += kMs;
    port.inject(le16(e.lo, e.hi, t));
    const GyroSample s = g.read(t);
    if (e.saturated) ++saturated;
    EXPECT_EQ(s.rate_z, e.rate);
    EXPECT_EQ(s.flags, e.saturated ? static_cast<std::uint32_t>(kGyroSaturated) : 0u) << e.rate;
    EXPECT_EQ(s.counters.saturated, saturated);
  }
  EXPECT_EQ(saturated, 2u);
  // One saturated sample among others flags the whole read: (32767 + 1) / 2 / 4096 = 4 rad/s.
  port.inject(le16(0xFF, 0x7F, t + kMs));
  port.inject(le16(0x01, 0x00, t + kMs));
  const GyroSample s = g.read(t + kMs);
  EXPECT_EQ(s.rate_z, 4.0);
  EXPECT_EQ(s.flags, static_cast<std::uint32_t>(kGyroSaturated));
  EXPECT_EQ(s.counters.saturated, 3u);
}

// Unsigned J1939-style field: its ends are 0 and 65535 LSB.
TEST_F(CanGyro, SaturationOfAnUnsignedFieldAtZeroAndAllOnes) {
  cfg.field.is_signed = false;
  cfg.offset = -32000.0 * kScale16;
  CanGyroSource g = make();
  port.inject(le16(0x00, 0x00, 1 * kMs));  // 0: -7.8125 rad/s, the low end
  GyroSample s = g.read(1 * kMs);
  EXPECT_EQ(s.rate_z, -7.8125);
  EXPECT_EQ(s.flags, static_cast<std::uint32_t>(kGyroSaturated));
  port.inject(le16(0x01, 0x00, 2 * kMs));  // 1: inside
  EXPECT_EQ(g.read(2 * kMs).flags, 0u);
  port.inject(le16(0xFF, 0xFF, 3 * kMs));  // 65535: 33535 / 4096 = 8.187255859375 rad/s
  s = g.read(3 * kMs);
  EXPECT_EQ(s.rate_z, 8.187255859375);
  EXPECT_EQ(s.flags, static_cast<std::uint32_t>(kGyroSaturated));
  EXPECT_EQ(s.counters.saturated, 2u);
}

TEST_F(CanGyro, ShortFrameWithOurIdIsInvalid) {
  CanGyroSource g = make();
  port.inject(le16(0x00, 0x10, 1 * kMs));  // 1 rad/s
  EXPECT_EQ(g.read(1 * kMs).rate_z, 1.0);
  port.inject(frame(kId, {0x00}, 2 * kMs));  // DLC 1 < 0 + 2 bytes
  GyroSample s = g.read(2 * kMs);
  EXPECT_EQ(s.flags, static_cast<std::uint32_t>(kGyroInvalid));
  EXPECT_EQ(s.counters.invalid, 1u);
  EXPECT_EQ(s.samples, 0u);
  EXPECT_EQ(s.rate_z, 1.0);     // the last rate is kept
  EXPECT_EQ(s.stamp, 1 * kMs);  // a short frame is no sample
  s = g.read(3 * kMs);          // the flag is for that read only
  EXPECT_EQ(s.flags, 0u);
  EXPECT_EQ(s.counters.invalid, 1u);
}

TEST_F(CanGyro, RemoteFramesAndForeignIdsAreIgnoredAndCounted) {
  CanGyroSource g = make();
  port.inject(le16(0x00, 0x10, 1 * kMs));  // 1 rad/s
  g.read(1 * kMs);
  CanFrame rtr = frame(kId, {}, 2 * kMs);
  rtr.rtr = true;
  rtr.len = 2;
  port.inject(rtr);
  port.inject(frame(kId + 1, {0x00, 0x20}, 2 * kMs));      // another 11-bit id
  port.inject(frame(kId, {0x00, 0x20}, 2 * kMs, true));    // our number as a 29-bit id
  port.inject(frame(0x7FF, {0xFF, 0x7F, 0, 0}, 2 * kMs));  // another id at the field's end
  const GyroSample s = g.read(3 * kMs);
  EXPECT_EQ(s.flags, 0u);
  EXPECT_EQ(s.samples, 0u);
  EXPECT_EQ(s.rate_z, 1.0);
  EXPECT_EQ(s.stamp, 1 * kMs);
  EXPECT_EQ(s.counters.saturated, 0u);
  EXPECT_EQ(s.counters.invalid, 0u);
  EXPECT_EQ(g.stats().frames, 5u);  // 1 + 4
  EXPECT_EQ(g.stats().remote, 1u);
  EXPECT_EQ(g.stats().foreign, 3u);
}

TEST_F(CanGyro, MaxFramesPerReadCapsAReadAndTheRestComesNext) {
  cfg.max_frames_per_read = 3;
  CanGyroSource g = make();
  // 1..5 rad/s (4096 k LSB = 0x1000 k: LE 00 10, 00 20, ...) at 1..5 ms.
  for (std::uint8_t k = 1; k <= 5; ++k)
    port.inject(le16(0x00, static_cast<std::uint8_t>(0x10 * k), k * kMs));
  // Read 1: frames 1..3, mean (1 + 2 + 3) / 3 = 2 rad/s, newest stamp 3 ms; capped.
  GyroSample s = g.read(6 * kMs);
  EXPECT_EQ(s.samples, 3u);
  EXPECT_EQ(s.rate_z, 2.0);
  EXPECT_EQ(s.stamp, 3 * kMs);
  EXPECT_EQ(g.stats().capped_reads, 1u);
  // Read 2: frames 4, 5, mean 4.5 rad/s, stamp 5 ms; not capped (2 < 3).
  s = g.read(7 * kMs);
  EXPECT_EQ(s.samples, 2u);
  EXPECT_EQ(s.rate_z, 4.5);
  EXPECT_EQ(s.stamp, 5 * kMs);
  EXPECT_EQ(s.counters.samples, 5u);
  EXPECT_EQ(g.stats().capped_reads, 1u);
  EXPECT_EQ(g.stats().frames, 5u);
}

TEST_F(CanGyro, FullScaleIsTheSmallerEndOfTheField) {
  // int16, 2^-12 rad/s per LSB: ends -32768 / 4096 = -8 and 32767 / 4096 = 7.999755859375.
  EXPECT_EQ(make().full_scale(), 32767.0 * kScale16);
  EXPECT_EQ(make().full_scale(), 7.999755859375);
  // int24, 2^-20: (2^23 - 1) / 2^20 = 8388607 / 1048576.
  cfg.field.width_bits = 24;
  cfg.scale = std::ldexp(1.0, -20);
  EXPECT_EQ(make().full_scale(), 8388607.0 / 1048576.0);
}

// read() and read_into() (into a sample holding garbage) agree field by field, over a sequence
// that passes through every flag.
TEST_F(CanGyro, ReadAndReadIntoAgree) {
  sim::SimCanPort port2{8, 512};
  CanGyroSource a = make();
  CanGyroSource b = CanGyroSource::create(port2, cfg).value();
  auto both = [&](const CanFrame& f) {
    port.inject(f);
    port2.inject(f);
  };
  struct Step {
    TimeNs now;
    std::vector<CanFrame> frames;
  };
  const Step steps[] = {
      {5 * kMs, {}},                                                        // starting
      {10 * kMs, {le16(0x00, 0x10, 9 * kMs), le16(0x00, 0x20, 10 * kMs)}},  // 1.5 rad/s
      {20 * kMs, {}},                                                       // kept
      {30 * kMs, {le16(0x00, 0x80, 30 * kMs)}},                             // saturated
      {40 * kMs, {frame(kId, {0x01}, 40 * kMs)}},                           // invalid
      {200 * kMs, {}},                                                      // stale
  };
  for (const Step& st : steps) {
    for (const CanFrame& f : st.frames) both(f);
    const GyroSample x = a.read(st.now);
    GyroSample y;
    y.rate_z = 123.0;
    y.stamp = 77;
    y.samples = 99;
    y.flags = 0xFF;
    y.counters.samples = 1234;
    b.read_into(st.now, y);
    EXPECT_EQ(x.rate_z, y.rate_z) << st.now;
    EXPECT_EQ(x.stamp, y.stamp) << st.now;
    EXPECT_EQ(x.samples, y.samples) << st.now;
    EXPECT_EQ(x.flags, y.flags) << st.now;
    EXPECT_EQ(x.counters.samples, y.counters.samples);
    EXPECT_EQ(x.counters.stale_events, y.counters.stale_events);
    EXPECT_EQ(x.counters.saturated, y.counters.saturated);
    EXPECT_EQ(x.counters.invalid, y.counters.invalid);
    EXPECT_EQ(x.counters.read_errors, y.counters.read_errors);
  }
  // The last step: 3 samples, 1 saturation, 1 invalid frame, one stale event (starting, before
  // the first frame at 10 ms, is none).
  const GyroSample last = a.read(210 * kMs);
  EXPECT_EQ(last.counters.samples, 3u);
  EXPECT_EQ(last.counters.saturated, 1u);
  EXPECT_EQ(last.counters.invalid, 1u);
  EXPECT_EQ(last.counters.stale_events, 1u);
}

}  // namespace
}  // namespace odo::drivers
