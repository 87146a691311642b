// Byte fields independent of the host's byte order, written once for every user: CAN payloads
// (protocol/, drivers' CAN encoder), the calibration record (calibration/), the simulated
// controller frames (sim_hal/). Little endian (Intel) unless the name says otherwise.
#pragma once

#include <cstddef>
#include <cstdint>

namespace odo {

// put_le: the low `n` (1..8) bytes of `v` into p[0..n), least significant first.
constexpr void put_le(std::uint8_t* p, std::size_t n, std::uint64_t v) noexcept {
  for (std::size_t i = 0; i < n; ++i) p[i] = static_cast<std::uint8_t>(v >> (8 * i));
}

// get_le: p[0..n) (1..8 bytes), least significant first, zero-extended.
constexpr std::uint64_t get_le(const std::uint8_t* p, std::size_t n) noexcept {
  std::uint64_t v = 0;
  for (std::size_t i = 0; i < n; ++i) v |= static_cast<std::uint64_t>(p[i]) << (8 * i);
  return v;
}

// get_be: p[0..n) (1..8 bytes), most significant first (Motorola order), zero-extended.
constexpr std::uint64_t get_be(const std::uint8_t* p, std::size_t n) noexcept {
  std::uint64_t v = 0;
  for (std::size_t i = 0; i < n; ++i) v = (v << 8) | p[i];
  return v;
}

// sign_extend: the low `bits` (1..64) bits of `v` as a two's-complement number.
constexpr std::int64_t sign_extend(std::uint64_t v, int bits) noexcept {
  const int shift = 64 - bits;
  return static_cast<std::int64_t>(v << shift) >> shift;
}

}  // namespace odo
