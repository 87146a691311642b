// The diffodom serial counts stream (protocol/serial_counts): CRC-16/CCITT-FALSE, COBS, the
// record layout and the byte-at-a-time decoder with every error kind and its resynchronisation.
// Expected bytes are derived by hand in the comments.
#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "odo/protocol/serial_counts.hpp"

namespace odo::protocol {
namespace {

using Bytes = std::vector<std::uint8_t>;

TEST(SerialCrc, HandDerivedVectors) {
  // Empty input: the init value 0xFFFF untouched.
  EXPECT_EQ(crc16_ccitt_false({}), 0xFFFF);
  // One byte 0x00: crc = 0xFFFF ^ (0x00 << 8) = 0xFFFF, then 8 shifts (top bit set: shift and
  // xor 0x1021): FFFF->EFDF->CF9F->8F1F->0E1F, then top bit clear: ->1C3E->387C->70F8->E1F0.
  const std::array<std::uint8_t, 1> zero{0x00};
  EXPECT_EQ(crc16_ccitt_false(zero), 0xE1F0);
  // One byte 0x80: crc = 0xFFFF ^ 0x8000 = 0x7FFF; top clear: ->FFFE; then set each time:
  // FFFE<<1=FFFC^1021=EFDD; DFBA^1021=CF9B; 9F36^1021=8F17; 1E2E^1021=0E0F; clear: 1C1E; 383C;
  // 7078.
  const std::array<std::uint8_t, 1> x80{0x80};
  EXPECT_EQ(crc16_ccitt_false(x80), 0x7078);
  // The catalogue's check value of CRC-16/CCITT-FALSE over "123456789" (Greg Cook's catalogue).
  const std::array<std::uint8_t, 9> check{'1', '2', '3', '4', '5', '6', '7', '8', '9'};
  EXPECT_EQ(crc16_ccitt_false(check), 0x29B1);
}

Bytes cobs(const Bytes& in) {
  Bytes out(in.size() + in.size() / 254 + 1);
  out.resize(cobs_encode(in, out));
  return out;
}

TEST(SerialCobs, HandDerivedVectors) {
  // Each block: code = 1 + its non-zero bytes; a block ending before the data does stands for
  // a zero. {00}: an empty block then an empty last block.
  EXPECT_EQ(cobs({0x00}), (Bytes{0x01, 0x01}));
  EXPECT_EQ(cobs({0x11, 0x22, 0x00, 0x33}), (Bytes{0x03, 0x11, 0x22, 0x02, 0x33}));
  EXPECT_EQ(cobs({0x11, 0x00, 0x00, 0x00}), (Bytes{0x02, 0x11, 0x01, 0x01, 0x01}));
  EXPECT_EQ(cobs({}), (Bytes{0x01}));
  // 254 non-zero bytes fill one block (code 0xFF, no zero implied); a last empty block follows.
  const Bytes run(254, 0x5A);
  const Bytes enc = cobs(run);
  ASSERT_EQ(enc.size(), 256u);
  EXPECT_EQ(enc[0], 0xFF);
  EXPECT_EQ(enc[255], 0x01);
  // Decoding inverts each of them.
  for (const Bytes& in : {Bytes{0x00}, Bytes{0x11, 0x22, 0x00, 0x33}, Bytes{0x11, 0, 0, 0}, run}) {
    Bytes out(in.size() + 1);
    const Bytes e = cobs(in);
    ASSERT_EQ(cobs_decode(e, out), static_cast<std::ptrdiff_t>(in.size()));
    out.resize(in.size());
    EXPECT_EQ(out, in);
  }
  // Malformed: a code running past the end, a zero inside, an output too small.
  Bytes out(8);
  EXPECT_EQ(cobs_decode(Bytes{0x05, 0x11}, out), -1);
  EXPECT_EQ(cobs_decode(Bytes{0x03, 0x11, 0x00}, out), -1);
  EXPECT_EQ(cobs_decode(Bytes{0x00}, out), -1);
  Bytes small(1);
  EXPECT_EQ(cobs_decode(Bytes{0x03, 0x11, 0x22}, small), -1);
  // Encoding into too small an output is refused.
  std::array<std::uint8_t, 2> tiny{};
  EXPECT_EQ(cobs_encode(Bytes{1, 2}, tiny), 0u);
}

// The record of the layout example: seq 0x0102, time 0x03040506 us, left +1, right -1, booted.
SerialCounts example() {
  return SerialCounts{
      .seq = 0x0102, .time_us = 0x03040506, .left = 1, .right = -1, .flags = kSerialFlagBooted};
}
// Payload, little-endian: 01 (version) 04 (flags) 02 01 (seq) 06 05 04 03 (time) 01 00 00 00
// (left) FF FF FF FF (right); its CRC-16/CCITT-FALSE is 0x3660 (too long to derive by hand here:
// Python's binascii.crc_hqx(payload, 0xFFFF), an independent implementation of the same
// polynomial and init, gives 0x3660), sent little-endian 60 36. COBS: 9 non-zero bytes then a
// zero -> code 0x0A; two more zeros -> 0x01, 0x01; the last 6 bytes -> 0x07; then the delimiter.
const Bytes kExampleFrame{0x0A, 0x01, 0x04, 0x02, 0x01, 0x06, 0x05, 0x04, 0x03, 0x01,
                          0x01, 0x01, 0x07, 0xFF, 0xFF, 0xFF, 0xFF, 0x60, 0x36, 0x00};

Bytes encode(const SerialCounts& s) {
  std::array<std::uint8_t, kSerialCountsFrameMax> buf{};
  const std::size_t n = encode_serial_counts(s, buf);
  return Bytes(buf.begin(), buf.begin() + static_cast<std::ptrdiff_t>(n));
}

TEST(SerialCountsFrame, LayoutByHand) {
  EXPECT_EQ(kSerialCountsFrameMax, 20u);
  EXPECT_EQ(encode(example()), kExampleFrame);
}

// push_all: every byte through the decoder; the results other than kNeedMore, in order.
std::vector<SerialDecodeResult> push_all(SerialCountsDecoder& d, const Bytes& bytes,
                                         std::vector<SerialCounts>* frames = nullptr) {
  std::vector<SerialDecodeResult> r;
  for (const std::uint8_t b : bytes) {
    const SerialDecodeResult x = d.push(b);
    if (x == SerialDecodeResult::kNeedMore) continue;
    r.push_back(x);
    if (x == SerialDecodeResult::kFrame && frames) frames->push_back(d.counts());
  }
  return r;
}

TEST(SerialCountsDecoder, ByteAtATimeRoundTrip) {
  SerialCountsDecoder d;
  // Only the delimiter completes a frame: every byte before it says "need more".
  for (std::size_t i = 0; i + 1 < kExampleFrame.size(); ++i)
    EXPECT_EQ(d.push(kExampleFrame[i]), SerialDecodeResult::kNeedMore) << i;
  ASSERT_EQ(d.push(0x00), SerialDecodeResult::kFrame);
  const SerialCounts& c = d.counts();
  EXPECT_EQ(c.seq, 0x0102);
  EXPECT_EQ(c.time_us, 0x03040506u);
  EXPECT_EQ(c.left, 1);
  EXPECT_EQ(c.right, -1);
  EXPECT_EQ(c.flags, kSerialFlagBooted);
  // Extremes round-trip (wrapping fields at their limits, every flag).
  const SerialCounts ext{
      .seq = 0xFFFF, .time_us = 0xFFFFFFFF, .left = INT32_MIN, .right = INT32_MAX, .flags = 0x07};
  ASSERT_EQ(push_all(d, encode(ext)), std::vector{SerialDecodeResult::kFrame});
  EXPECT_EQ(d.counts().seq, 0xFFFF);
  EXPECT_EQ(d.counts().time_us, 0xFFFFFFFFu);
  EXPECT_EQ(d.counts().left, INT32_MIN);
  EXPECT_EQ(d.counts().right, INT32_MAX);
  EXPECT_EQ(d.counts().flags, 0x07);
  // Idle delimiters between frames are not errors.
  EXPECT_TRUE(push_all(d, Bytes{0, 0, 0}).empty());
}

// frame_of: a raw record (payload + CRC as given) COBS-framed.
Bytes frame_of(Bytes rec) {
  Bytes f = cobs(rec);
  f.push_back(0x00);
  return f;
}
// record_of: payload with its correct CRC appended.
Bytes record_of(Bytes payload) {
  const std::uint16_t crc = crc16_ccitt_false(payload);
  payload.push_back(static_cast<std::uint8_t>(crc));
  payload.push_back(static_cast<std::uint8_t>(crc >> 8));
  return payload;
}

TEST(SerialCountsDecoder, EveryErrorKind) {
  SerialCountsDecoder d;
  using R = SerialDecodeResult;
  // Bad COBS: code 0x05 announces 4 bytes, the delimiter comes after 1.
  EXPECT_EQ(push_all(d, Bytes{0x05, 0x11, 0x00}), std::vector{R::kBadCobs});
  // Bad length: valid COBS of a 17-byte record (one short).
  Bytes payload{1, 0, 1, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0};  // seq 1, time 1, left 1, right 1
  Bytes short_rec = record_of(payload);
  short_rec.pop_back();
  EXPECT_EQ(push_all(d, frame_of(short_rec)), std::vector{R::kBadLength});
  // Bad length: 40 non-zero bytes without a delimiter overrun the buffer, reported once at the
  // delimiter.
  Bytes run(40, 0x33);
  run.push_back(0x00);
  EXPECT_EQ(push_all(d, run), std::vector{R::kBadLength});
  // CRC mismatch: the example with its left counter's 0x01 changed to 0x02 (index 9 on the
  // wire), CRC unchanged.
  Bytes bad = kExampleFrame;
  bad[9] = 0x02;
  EXPECT_EQ(push_all(d, bad), std::vector{R::kCrcMismatch});
  // Bad version: version 2 with a correct CRC.
  payload[0] = 2;
  EXPECT_EQ(push_all(d, frame_of(record_of(payload))), std::vector{R::kBadVersion});
  // And version 1 of the same payload is accepted.
  payload[0] = 1;
  EXPECT_EQ(push_all(d, frame_of(record_of(payload))), std::vector{R::kFrame});
  EXPECT_EQ(d.counts().seq, 1);
  EXPECT_EQ(d.counts().time_us, 1u);
  EXPECT_EQ(d.counts().left, 1);
  EXPECT_EQ(d.counts().right, 1);
}

// Version 2 (issue 38): two wheels per side, seq 0x0102, time 0x03040506 us, left wheels +1 and
// +2, right wheels -1 and +3, left wheel 2 faulted (wheel_faults bit 1). Payload, little-endian:
// 02 (version) 00 (flags) 02 01 (seq) 06 05 04 03 (time) 02 (wheels per side) 02 (faults)
// 01 00 00 00, 02 00 00 00 (left) FF FF FF FF, 03 00 00 00 (right): 26 bytes; CRC 0xC26B (Python's
// binascii.crc_hqx(payload, 0xFFFF)), sent 6B C2. COBS: 02 (the version byte then a zero),
// 0A (9 bytes up to the zero after the first left count's 01), 02 02 .. as below.
const Bytes kExampleFrameV2{0x02, 0x02, 0x0A, 0x02, 0x01, 0x06, 0x05, 0x04, 0x03, 0x02,
                            0x02, 0x01, 0x01, 0x01, 0x02, 0x02, 0x01, 0x01, 0x06, 0xFF,
                            0xFF, 0xFF, 0xFF, 0x03, 0x01, 0x01, 0x03, 0x6B, 0xC2, 0x00};

TEST(SerialCountsFrame, Version2LayoutByHandAndRoundTrip) {
  SerialCounts c{.seq = 0x0102, .time_us = 0x03040506, .left = 1, .right = -1, .flags = 0};
  c.wheels_per_side = 2;
  c.more_left[0] = 2;
  c.more_right[0] = 3;
  c.wheel_faults = 0x02;
  std::array<std::uint8_t, kSerialCountsFrameMaxV2> buf{};
  const std::size_t n = encode_serial_counts_v2(c, buf);
  EXPECT_EQ(Bytes(buf.begin(), buf.begin() + static_cast<std::ptrdiff_t>(n)), kExampleFrameV2);
  EXPECT_EQ(kSerialCountsFrameMaxV2, 46u);  // 4 wheels: 10 + 32 + 2 = 44, COBS +1, 0x00 +1
  // A host reading several wheels decodes it; a version 1 host (the default decoder) finds it
  // longer than any record it knows, as it always did.
  SerialCountsDecoder several(true);
  ASSERT_EQ(push_all(several, kExampleFrameV2), std::vector{SerialDecodeResult::kFrame});
  const SerialCounts& d = several.counts();
  EXPECT_EQ(d.wheels_per_side, 2);
  EXPECT_EQ(d.seq, 0x0102);
  EXPECT_EQ(d.time_us, 0x03040506u);
  EXPECT_EQ(d.left, 1);
  EXPECT_EQ(d.more_left[0], 2);
  EXPECT_EQ(d.right, -1);
  EXPECT_EQ(d.more_right[0], 3);
  EXPECT_EQ(d.wheel_faults, 0x02);
  SerialCountsDecoder v1;
  EXPECT_EQ(push_all(v1, kExampleFrameV2), std::vector{SerialDecodeResult::kBadLength});
  // An old board's version 1 record still decodes on the several-wheels decoder (one wheel).
  ASSERT_EQ(push_all(several, kExampleFrame), std::vector{SerialDecodeResult::kFrame});
  EXPECT_EQ(several.counts().wheels_per_side, 1);
  EXPECT_EQ(several.counts().left, 1);
  EXPECT_EQ(several.counts().right, -1);
  // Four wheels per side, extremes; every fault bit.
  c.wheels_per_side = 4;
  c.more_left = {INT32_MIN, 0, INT32_MAX};
  c.more_right = {-7, 8, -9};
  c.wheel_faults = 0xFF;
  const std::size_t n4 = encode_serial_counts_v2(c, buf);
  EXPECT_EQ(n4, 46u);
  ASSERT_EQ(push_all(several, Bytes(buf.begin(), buf.begin() + static_cast<std::ptrdiff_t>(n4))),
            std::vector{SerialDecodeResult::kFrame});
  EXPECT_EQ(several.counts().more_left, c.more_left);
  EXPECT_EQ(several.counts().more_right, c.more_right);
  EXPECT_EQ(several.counts().wheel_faults, 0xFF);
  // A version 2 record whose wheel count disagrees with its length: bad length (CRC good).
  Bytes payload(26, 0);
  payload[0] = 2;
  payload[8] = 3;  // says 3 wheels: 10 + 24 = 34 bytes, not 26
  EXPECT_EQ(push_all(several, frame_of(record_of(payload))),
            std::vector{SerialDecodeResult::kBadLength});
  payload[8] = 2;
  payload[0] = 3;  // a version after 2
  EXPECT_EQ(push_all(several, frame_of(record_of(payload))),
            std::vector{SerialDecodeResult::kBadVersion});
}

TEST(SerialCountsDecoder, ResynchronisesAfterGarbage) {
  using R = SerialDecodeResult;
  SerialCountsDecoder d;
  // Joined mid-frame (the tail of the example), then garbage with a zero in it, then an ASCII
  // line (a wrong protocol), then two good frames: the good frames come out intact.
  Bytes stream(kExampleFrame.begin() + 7, kExampleFrame.end());
  for (std::uint8_t b : {0x7E, 0x00, 0x13, 0x37, 0xFF, 0x00}) stream.push_back(b);
  for (char ch : std::string("1234 5678\r\n")) stream.push_back(static_cast<std::uint8_t>(ch));
  stream.push_back(0x00);
  SerialCounts a = example();
  SerialCounts b = example();
  b.seq = 0x0103;
  b.left = 123456;
  for (const SerialCounts& s : {a, b})
    for (std::uint8_t x : encode(s)) stream.push_back(x);
  std::vector<SerialCounts> frames;
  const auto r = push_all(d, stream, &frames);
  ASSERT_EQ(r.size(), 6u);
  // The tail: 12 COBS bytes starting with 0x04 (code 4 then 3 bytes...): not a record.
  EXPECT_NE(r[0], R::kFrame);
  EXPECT_NE(r[1], R::kFrame);  // 0x7E alone: code 0x7E overruns
  EXPECT_EQ(r[1], R::kBadCobs);
  EXPECT_NE(r[2], R::kFrame);  // 13 37 FF
  EXPECT_NE(r[3], R::kFrame);  // the ASCII line
  EXPECT_EQ(r[4], R::kFrame);
  EXPECT_EQ(r[5], R::kFrame);
  ASSERT_EQ(frames.size(), 2u);
  EXPECT_EQ(frames[0].seq, 0x0102);
  EXPECT_EQ(frames[1].seq, 0x0103);
  EXPECT_EQ(frames[1].left, 123456);
  // A frame cut short by the line dropping: reset() discards it; the next frame is intact.
  SerialCountsDecoder d2;
  for (std::size_t i = 0; i < 10; ++i) d2.push(kExampleFrame[i]);
  d2.reset();
  EXPECT_EQ(push_all(d2, kExampleFrame), std::vector{R::kFrame});
}

}  // namespace
}  // namespace odo::protocol
