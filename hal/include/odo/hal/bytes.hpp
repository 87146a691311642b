// Byte fields independent of the host's byte order, written once for every user: CAN payloads
// (protocol/, drivers' CAN encoder), the calibration record (calibration/), the simulated
// controller frames (sim_hal/). Little endian (Intel) unless the name says otherwise.
#pragma once

#include <bit>
#include <cstddef>
#include <cstdint>
#include <span>
#include <type_traits>

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

// put_le: v (an integer or a double) at byte `off` of `b`, least significant byte first: the
// fields of byte-exact records (the calibration record, the loop's state record).
template <class T>
void put_le(std::span<std::uint8_t> b, std::size_t off, T v) noexcept {
  static_assert(std::is_arithmetic_v<T> && sizeof(T) <= 8);
  std::uint64_t u = 0;
  if constexpr (std::is_floating_point_v<T>) {
    u = std::bit_cast<std::uint64_t>(static_cast<double>(v));
    static_assert(sizeof(T) == 8, "records store doubles only");
  } else {
    u = static_cast<std::uint64_t>(v);
  }
  put_le(b.data() + off, sizeof(T), u);
}

// get_le: the T stored by put_le at byte `off` of `b`.
template <class T>
T get_le(std::span<const std::uint8_t> b, std::size_t off) noexcept {
  const std::uint64_t u = get_le(b.data() + off, sizeof(T));
  if constexpr (std::is_floating_point_v<T>) {
    return std::bit_cast<double>(u);
  } else {
    return static_cast<T>(u);
  }
}

}  // namespace odo
