// CRC-32/ISO-HDLC (zlib's crc32), the check of every record the project writes (calibration
// record, state record). In hal/ so that each room that writes or reads a record uses this one
// definition without linking the room that happens to own another record.
#pragma once

#include <array>
#include <cstdint>
#include <span>

namespace odo {

namespace detail {
// The reflected polynomial 0xEDB88320's byte table, built at compile time (1 KiB of .rodata).
constexpr std::array<std::uint32_t, 256> make_crc32_table() noexcept {
  std::array<std::uint32_t, 256> t{};
  for (std::uint32_t i = 0; i < 256; ++i) {
    std::uint32_t c = i;
    for (int k = 0; k < 8; ++k) c = (c & 1U) ? 0xEDB88320U ^ (c >> 1) : c >> 1;
    t[i] = c;
  }
  return t;
}
inline constexpr auto kCrc32Table = make_crc32_table();
}  // namespace detail

// crc32: CRC-32/ISO-HDLC of `data` ("123456789" -> 0xCBF43926).
constexpr std::uint32_t crc32(std::span<const std::uint8_t> data) noexcept {
  std::uint32_t c = 0xFFFFFFFFU;
  for (std::uint8_t b : data) c = detail::kCrc32Table[(c ^ b) & 0xFFU] ^ (c >> 8);
  return c ^ 0xFFFFFFFFU;
}

}  // namespace odo
