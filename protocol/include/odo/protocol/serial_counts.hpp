// The diffodom serial counts stream (README "Serial counts stream"): what the project's
// microcontroller firmware sends the Linux board over a UART / USB CDC-ACM line, one record per
// sample. Record = payload (16 bytes, little-endian: u8 version, u8 flags, u16 seq, u32 time_us,
// i32 left, i32 right) + CRC-16/CCITT-FALSE of the payload (u16 little-endian), COBS-encoded
// (19 bytes) and terminated by one 0x00: 20 bytes on the wire. Portable code for the host and the
// microcontroller alike: no allocation, no exceptions, no I/O. (The first contract text said
// 14 / 18 bytes; its own field list adds up to 16 / 20, which is what is sent.)
//
// Version 2 (issue 38: N = 1..4 encoders per side): payload = u8 version (2), u8 flags, u16 seq,
// u32 time_us, u8 wheels_per_side N, u8 wheel_faults (bit k: left wheel k faulted this sample,
// bit 4 + k: right wheel k), i32 left[N], i32 right[N] (10 + 8 N bytes) + CRC, COBS, 0x00: at
// most 46 bytes on the wire. A board with one wheel per side sends version 1 (the host reads
// both), so an old board and an old host keep working.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

namespace odo::protocol {

inline constexpr std::uint8_t kSerialCountsVersion = 1;
inline constexpr std::size_t kSerialCountsPayload = 16;  // version .. right
inline constexpr std::size_t kSerialCountsRecord = 18;   // payload + CRC
// One frame on the wire: COBS adds one byte to a record under 254 bytes, plus the delimiter.
inline constexpr std::size_t kSerialCountsFrameMax = kSerialCountsRecord + 2;

// Version 2 (several wheels per side).
inline constexpr std::uint8_t kSerialCountsVersion2 = 2;
inline constexpr int kSerialMaxWheelsPerSide = 4;  // hal's kMaxWheelsPerSide (checked)
inline constexpr std::size_t kSerialCountsPayloadV2Max = 10 + 8 * kSerialMaxWheelsPerSide;
inline constexpr std::size_t kSerialCountsRecordV2Max = kSerialCountsPayloadV2Max + 2;
inline constexpr std::size_t kSerialCountsFrameMaxV2 = kSerialCountsRecordV2Max + 2;

// SerialCounts::flags bits.
inline constexpr std::uint8_t kSerialFlagFaultLeft = 0x01;   // the left counter reports a fault
inline constexpr std::uint8_t kSerialFlagFaultRight = 0x02;  // the right counter reports a fault
inline constexpr std::uint8_t kSerialFlagBooted = 0x04;      // controller booted: counters from 0

// One sample of the controller.
struct SerialCounts {
  std::uint16_t seq = 0;      // +1 per record, wraps
  std::uint32_t time_us = 0;  // controller's own clock [us], wraps (~71.6 min)
  std::int32_t left = 0;      // raw wheel counters (wrap freely; the host takes wrap-aware deltas)
  std::int32_t right = 0;
  std::uint8_t flags = 0;  // kSerialFlag* bits
  // Version 2: wheels 2..N of each side (left/right above are wheel 1) and the per-wheel faults.
  std::uint8_t wheels_per_side = 1;  // 1: a version 1 record
  std::array<std::int32_t, kSerialMaxWheelsPerSide - 1> more_left{};
  std::array<std::int32_t, kSerialMaxWheelsPerSide - 1> more_right{};
  std::uint8_t wheel_faults = 0;  // bit k: left wheel k (0-based), bit 4 + k: right wheel k
};

// crc16_ccitt_false: CRC-16/CCITT-FALSE (poly 0x1021, init 0xFFFF, no reflection, no xorout).
std::uint16_t crc16_ccitt_false(std::span<const std::uint8_t> data) noexcept;

// cobs_encode: `in` COBS-encoded into `out` (no delimiter); returns the encoded length, 0 when
// `out` is too small (it needs in.size() + in.size() / 254 + 1 bytes).
std::size_t cobs_encode(std::span<const std::uint8_t> in, std::span<std::uint8_t> out) noexcept;
// cobs_decode: a COBS block (no delimiter) decoded into `out`; returns the decoded length, or -1
// when the block is malformed (a zero byte, a code running past the end) or `out` is too small.
std::ptrdiff_t cobs_decode(std::span<const std::uint8_t> in, std::span<std::uint8_t> out) noexcept;

// encode_serial_counts: one record as a COBS frame terminated by 0x00; returns its length in
// bytes (always kSerialCountsFrameMax).
std::size_t encode_serial_counts(const SerialCounts& s,
                                 std::span<std::uint8_t, kSerialCountsFrameMax> out) noexcept;

// encode_serial_counts_v2: one record with s.wheels_per_side (1..4) wheels per side as a version 2
// COBS frame terminated by 0x00; returns its length (14 + 8 N bytes with N wheels per side).
std::size_t encode_serial_counts_v2(const SerialCounts& s,
                                    std::span<std::uint8_t, kSerialCountsFrameMaxV2> out) noexcept;

// What one byte pushed into the decoder completed.
enum class SerialDecodeResult : std::uint8_t {
  kNeedMore,     // no delimiter yet (or an empty frame between two delimiters)
  kFrame,        // a valid record: SerialCountsDecoder::counts()
  kBadCobs,      // the frame is not valid COBS
  kBadLength,    // the frame decodes to no record's length (18; v2: 12 + 8 N), or overran
  kCrcMismatch,  // the record's CRC does not match its payload
  kBadVersion,   // CRC good but a version this host does not read
};

// SerialCountsDecoder: byte-at-a-time decoder of the stream; no allocation. Resynchronises on
// every 0x00, so after garbage the next whole frame decodes.
class SerialCountsDecoder {
 public:
  // several_wheels false: version 1 records only (frames longer than one overrun, as they always
  // did); true: version 1 and version 2 records.
  explicit SerialCountsDecoder(bool several_wheels = false) noexcept
      : limit_(several_wheels ? kSerialCountsFrameMaxV2 - 1 : kSerialCountsFrameMax - 1),
        several_(several_wheels) {}
  // push: one received byte; the result says whether it completed a frame and how.
  SerialDecodeResult push(std::uint8_t byte) noexcept;
  // counts: the last valid record (after push returned kFrame).
  const SerialCounts& counts() const noexcept { return counts_; }
  // reset: drop a partial frame (e.g. after reopening the line).
  void reset() noexcept {
    len_ = 0;
    overrun_ = false;
  }

 private:
  SerialDecodeResult finish() noexcept;

  SerialDecodeResult decode_v2(std::span<const std::uint8_t> rec) noexcept;

  std::array<std::uint8_t, kSerialCountsFrameMaxV2 - 1> buf_{};  // the COBS block being received
  std::size_t len_ = 0;
  std::size_t limit_;     // bytes of buf_ in use: the longest frame read, without delimiter
  bool several_;          // version 2 records are read
  bool overrun_ = false;  // more bytes than a frame holds since the last delimiter
  SerialCounts counts_{};
};

}  // namespace odo::protocol
