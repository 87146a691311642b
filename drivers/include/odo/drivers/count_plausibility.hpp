// Helpers shared by the counter backends (HCTL-1100, CAN): wrap-aware steps of a counter of a
// given width, and the implausible-jump test (a step the wheel cannot physically make).
#pragma once

#include <cmath>
#include <cstdint>

namespace odo::drivers {

// wrap_bits: the low `bits` bits of v (1..64), sign-extended (two's complement) [counts].
constexpr std::int64_t wrap_bits(std::int64_t v, int bits) noexcept {
  if (bits >= 64) return v;
  const int shift = 64 - bits;
  return static_cast<std::int64_t>(static_cast<std::uint64_t>(v) << shift) >> shift;
}

// wrap_sub: (a - b) modulo 2^bits, sign-extended; never overflows, also for 64-bit counters
// (the arithmetic is done unsigned) [counts].
constexpr std::int64_t wrap_sub(std::int64_t a, std::int64_t b, int bits) noexcept {
  return wrap_bits(
      static_cast<std::int64_t>(static_cast<std::uint64_t>(a) - static_cast<std::uint64_t>(b)),
      bits);
}

// wrap_add: (a + b) modulo 2^bits, sign-extended, without overflow [counts].
constexpr std::int64_t wrap_add(std::int64_t a, std::int64_t b, int bits) noexcept {
  return wrap_bits(
      static_cast<std::int64_t>(static_cast<std::uint64_t>(a) + static_cast<std::uint64_t>(b)),
      bits);
}

// implausible_step: true when |step| [counts] exceeds what a wheel at max_counts_per_s
// [counts/s] can move in dt [s], plus `slack` [counts] (read-out jitter, quantisation).
inline bool implausible_step(std::int64_t step, double max_counts_per_s, double dt,
                             double slack) noexcept {
  return std::fabs(static_cast<double>(step)) > max_counts_per_s * dt + slack;
}

}  // namespace odo::drivers
