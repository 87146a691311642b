#include "odo/protocol/serial_counts.hpp"

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

std::uint16_t crc16_ccitt_false(std::span<const std::uint8_t> data) noexcept {
  // Bitwise rather than a 512-byte table: 16 bytes per record, and the microcontroller's flash
  // is worth more than the few hundred cycles.
  std::uint16_t crc = 0xFFFF;
  for (const std::uint8_t b : data) {
    crc = static_cast<std::uint16_t>(crc ^ (b << 8));
    for (int i = 0; i < 8; ++i)
      crc = static_cast<std::uint16_t>((crc & 0x8000) ? (crc << 1) ^ 0x1021 : crc << 1);
  }
  return crc;
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
  if (len_ < buf_.size())
    buf_[len_++] = byte;
  else
    overrun_ = true;  // reported at the delimiter, which is where the stream resynchronises
  return SerialDecodeResult::kNeedMore;
}

SerialDecodeResult SerialCountsDecoder::finish() noexcept {
  const std::size_t len = len_;
  const bool overrun = overrun_;
  reset();
  if (len == 0 && !overrun) return SerialDecodeResult::kNeedMore;  // idle delimiters
  if (overrun) return SerialDecodeResult::kBadLength;
  std::array<std::uint8_t, kSerialCountsRecord + 1> rec{};  // one spare: longer is detected
  const std::ptrdiff_t n = cobs_decode(std::span(buf_).first(len), rec);
  if (n < 0) return SerialDecodeResult::kBadCobs;
  if (static_cast<std::size_t>(n) != kSerialCountsRecord) return SerialDecodeResult::kBadLength;
  if (crc16_ccitt_false(std::span(rec).first<kSerialCountsPayload>()) != get_u16(&rec[16]))
    return SerialDecodeResult::kCrcMismatch;
  if (rec[0] != kSerialCountsVersion) return SerialDecodeResult::kBadVersion;
  counts_.flags = rec[1];
  counts_.seq = get_u16(&rec[2]);
  counts_.time_us = get_u32(&rec[4]);
  counts_.left = static_cast<std::int32_t>(get_u32(&rec[8]));
  counts_.right = static_cast<std::int32_t>(get_u32(&rec[12]));
  return SerialDecodeResult::kFrame;
}

}  // namespace odo::protocol
