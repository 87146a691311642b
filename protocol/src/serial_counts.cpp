#include "odo/protocol/serial_counts.hpp"

#include <array>

namespace odo::protocol {
namespace {

void put_u16(std::uint8_t* p, std::uint16_t v) noexcept {
  p[0] = static_cast<std::uint8_t>(v);
  p[1] = static_cast<std::uint8_t>(v >> 8);
}
void put_u32(std::uint8_t* p, std::uint32_t v) noexcept {
  for (int i = 0; i < 4; ++i) p[i] = static_cast<std::uint8_t>(v >> (8 * i));
}
std::uint16_t get_u16(const std::uint8_t* p) noexcept {
  return static_cast<std::uint16_t>(p[0] | (p[1] << 8));
}
std::uint32_t get_u32(const std::uint8_t* p) noexcept {
  std::uint32_t v = 0;
  for (int i = 0; i < 4; ++i) v |= static_cast<std::uint32_t>(p[i]) << (8 * i);
  return v;
}

}  // namespace

namespace {

// The CRC of each 4-bit value in the top nibble, shifted out through the polynomial 0x1021:
// a nibble at a time needs 32 bytes of table where a byte at a time needs 512, and it is ~6x
// fewer instructions than a bit at a time (~1000 a record on a Cortex-M4 before).
constexpr std::array<std::uint16_t, 16> make_crc16_nibbles() noexcept {
  std::array<std::uint16_t, 16> t{};
  for (unsigned n = 0; n < 16; ++n) {
    unsigned c = n << 12;
    for (int i = 0; i < 4; ++i) c = (c & 0x8000U) ? (c << 1) ^ 0x1021U : c << 1;
    t[n] = static_cast<std::uint16_t>(c);
  }
  return t;
}
constexpr auto kCrc16Nibbles = make_crc16_nibbles();

}  // namespace

std::uint16_t crc16_ccitt_false(std::span<const std::uint8_t> data) noexcept {
  unsigned crc = 0xFFFF;
  for (const std::uint8_t b : data) {
    crc = ((crc << 4) & 0xFFFFU) ^ kCrc16Nibbles[(crc >> 12) ^ (b >> 4U)];
    crc = ((crc << 4) & 0xFFFFU) ^ kCrc16Nibbles[(crc >> 12) ^ (b & 0xFU)];
  }
  return static_cast<std::uint16_t>(crc);
}

std::size_t cobs_encode(std::span<const std::uint8_t> in, std::span<std::uint8_t> out) noexcept {
  if (out.size() < in.size() + in.size() / 254 + 1) return 0;
  std::size_t code_at = 0;  // where the current block's code byte goes
  std::size_t o = 1;
  std::uint8_t code = 1;  // 1 + the block's non-zero bytes so far
  for (const std::uint8_t b : in) {
    if (b != 0) {
      out[o++] = b;
      ++code;
    }
    // A zero ends the block; so does a full block of 254 non-zero bytes (code 0xFF, no zero).
    if (b == 0 || code == 0xFF) {
      out[code_at] = code;
      code_at = o++;
      code = 1;
    }
  }
  out[code_at] = code;
  return o;
}

std::ptrdiff_t cobs_decode(std::span<const std::uint8_t> in, std::span<std::uint8_t> out) noexcept {
  std::size_t i = 0;
  std::size_t o = 0;
  while (i < in.size()) {
    const std::uint8_t code = in[i++];
    if (code == 0 || i + code - 1 > in.size()) return -1;
    for (std::size_t k = 1; k < code; ++k) {
      if (in[i] == 0 || o >= out.size()) return -1;
      out[o++] = in[i++];
    }
    // Every block but a full one (0xFF) and the last stands for a zero after its bytes.
    if (code != 0xFF && i < in.size()) {
      if (o >= out.size()) return -1;
      out[o++] = 0;
    }
  }
  return static_cast<std::ptrdiff_t>(o);
}

std::size_t encode_serial_counts(const SerialCounts& s,
                                 std::span<std::uint8_t, kSerialCountsFrameMax> out) noexcept {
  std::array<std::uint8_t, kSerialCountsRecord> rec{};
  rec[0] = kSerialCountsVersion;
  rec[1] = s.flags;
  put_u16(&rec[2], s.seq);
  put_u32(&rec[4], s.time_us);
  put_u32(&rec[8], static_cast<std::uint32_t>(s.left));
  put_u32(&rec[12], static_cast<std::uint32_t>(s.right));
  put_u16(&rec[16], crc16_ccitt_false(std::span(rec).first<kSerialCountsPayload>()));
  const std::size_t n = cobs_encode(rec, out.first<kSerialCountsFrameMax - 1>());
  out[n] = 0;
  return n + 1;
}

SerialDecodeResult SerialCountsDecoder::push(std::uint8_t byte) noexcept {
  if (byte == 0) return finish();
  if (len_ < limit_)
    buf_[len_++] = byte;
  else
    overrun_ = true;  // reported at the delimiter, which is where the stream resynchronises
  return SerialDecodeResult::kNeedMore;
}

std::size_t encode_serial_counts_v2(const SerialCounts& s,
                                    std::span<std::uint8_t, kSerialCountsFrameMaxV2> out) noexcept {
  std::array<std::uint8_t, kSerialCountsRecordV2Max> rec{};
  const int n = s.wheels_per_side < 1
                    ? 1
                    : (s.wheels_per_side > kSerialMaxWheelsPerSide ? kSerialMaxWheelsPerSide
                                                                   : s.wheels_per_side);
  rec[0] = kSerialCountsVersion2;
  rec[1] = s.flags;
  put_u16(&rec[2], s.seq);
  put_u32(&rec[4], s.time_us);
  rec[8] = static_cast<std::uint8_t>(n);
  rec[9] = s.wheel_faults;
  std::size_t at = 10;
  for (int side = 0; side < 2; ++side) {
    for (int k = 0; k < n; ++k, at += 4) {
      const auto& more = side == 0 ? s.more_left : s.more_right;
      const std::int32_t v =
          k == 0 ? (side == 0 ? s.left : s.right) : more[static_cast<std::size_t>(k - 1)];
      put_u32(&rec[at], static_cast<std::uint32_t>(v));
    }
  }
  put_u16(&rec[at], crc16_ccitt_false(std::span(rec).first(at)));
  const std::size_t len = cobs_encode(std::span(rec).first(at + 2), out.first(out.size() - 1));
  out[len] = 0;
  return len + 1;
}

SerialDecodeResult SerialCountsDecoder::finish() noexcept {
  const std::size_t len = len_;
  const bool overrun = overrun_;
  reset();
  if (len == 0 && !overrun) return SerialDecodeResult::kNeedMore;  // idle delimiters
  if (overrun) return SerialDecodeResult::kBadLength;
  std::array<std::uint8_t, kSerialCountsRecordV2Max + 1> rec{};  // one spare: longer is detected
  const std::ptrdiff_t decoded = cobs_decode(std::span(buf_).first(len), rec);
  if (decoded < 0) return SerialDecodeResult::kBadCobs;
  const auto n = static_cast<std::size_t>(decoded);
  // The record lengths: 18 (version 1) and 12 + 8 N (version 2, N = 1..4).
  const bool v2_length = several_ && n >= 20 && n <= kSerialCountsRecordV2Max && (n - 12) % 8 == 0;
  if (n != kSerialCountsRecord && !v2_length) return SerialDecodeResult::kBadLength;
  if (crc16_ccitt_false(std::span(rec).first(n - 2)) != get_u16(&rec[n - 2]))
    return SerialDecodeResult::kCrcMismatch;
  if (n != kSerialCountsRecord) return decode_v2(std::span(rec).first(n));
  if (rec[0] != kSerialCountsVersion) return SerialDecodeResult::kBadVersion;
  counts_ = SerialCounts{};
  counts_.flags = rec[1];
  counts_.seq = get_u16(&rec[2]);
  counts_.time_us = get_u32(&rec[4]);
  counts_.left = static_cast<std::int32_t>(get_u32(&rec[8]));
  counts_.right = static_cast<std::int32_t>(get_u32(&rec[12]));
  return SerialDecodeResult::kFrame;
}

SerialDecodeResult SerialCountsDecoder::decode_v2(std::span<const std::uint8_t> rec) noexcept {
  if (rec[0] != kSerialCountsVersion2) return SerialDecodeResult::kBadVersion;
  const int n = rec[8];
  if (n < 1 || n > kSerialMaxWheelsPerSide || rec.size() != 12 + 8 * static_cast<std::size_t>(n))
    return SerialDecodeResult::kBadLength;
  counts_ = SerialCounts{};
  counts_.flags = rec[1];
  counts_.seq = get_u16(&rec[2]);
  counts_.time_us = get_u32(&rec[4]);
  counts_.wheels_per_side = static_cast<std::uint8_t>(n);
  counts_.wheel_faults = rec[9];
  std::size_t at = 10;
  for (int side = 0; side < 2; ++side) {
    for (int k = 0; k < n; ++k, at += 4) {
      const auto v = static_cast<std::int32_t>(get_u32(&rec[at]));
      auto& more = side == 0 ? counts_.more_left : counts_.more_right;
      (k == 0 ? (side == 0 ? counts_.left : counts_.right)
              : more[static_cast<std::size_t>(k - 1)]) = v;
    }
  }
  return SerialDecodeResult::kFrame;
}

}  // namespace odo::protocol
