// Little-endian field access of byte-exact records, independent of the host's byte order (the
// calibration record and the loop's state record share it).
#pragma once

#include <bit>
#include <cstddef>
#include <cstdint>
#include <span>
#include <type_traits>

namespace odo::calib {

// put_le: writes v (an integer or a double) at byte `off` of `b`, least significant byte first.
template <class T>
void put_le(std::span<std::uint8_t> b, std::size_t off, T v) noexcept {
  std::uint64_t u = 0;
  if constexpr (std::is_same_v<T, double>) {
    u = std::bit_cast<std::uint64_t>(v);
  } else {
    u = static_cast<std::uint64_t>(v);
  }
  for (std::size_t i = 0; i < sizeof(T); ++i) b[off + i] = static_cast<std::uint8_t>(u >> (8 * i));
}

// get_le: the T stored by put_le at byte `off` of `b`.
template <class T>
T get_le(std::span<const std::uint8_t> b, std::size_t off) noexcept {
  std::uint64_t u = 0;
  for (std::size_t i = 0; i < sizeof(T); ++i)
    u |= static_cast<std::uint64_t>(b[off + i]) << (8 * i);
  if constexpr (std::is_same_v<T, double>) {
    return std::bit_cast<double>(u);
  } else {
    return static_cast<T>(u);
  }
}

}  // namespace odo::calib
