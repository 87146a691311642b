// Wrap-aware differences of two's-complement hardware counters of 16 to 64 bits.
#pragma once

#include <cstdint>

#include "odo/hal/result.hpp"

namespace odo {

// wrap_delta: signed difference cur - prev of two readings of a `bits`-wide counter, taking the
// shortest way round the wrap (|delta| < 2^(bits-1)). Readings may be given signed or unsigned;
// only their low `bits` bits are used. bits must be in [16, 64] (checked by the caller once).
constexpr std::int64_t wrap_delta(std::int64_t prev, std::int64_t cur, int bits) noexcept {
  // Unsigned arithmetic wraps modulo 2^64 without UB; shifting the difference up to the top of
  // the word and back down (arithmetic shift) sign-extends it from `bits` bits.
  const std::uint64_t diff = static_cast<std::uint64_t>(cur) - static_cast<std::uint64_t>(prev);
  const int shift = 64 - bits;
  return static_cast<std::int64_t>(diff << shift) >> shift;
}

// counter_value: reported + rejected modulo 2^bits, sign-extended: the counter's own value when a
// backend reports `reported` after leaving out `rejected` counts of implausible jumps [counts].
constexpr std::int64_t counter_value(std::int64_t reported, std::int64_t rejected,
                                     int bits) noexcept {
  const std::uint64_t sum =
      static_cast<std::uint64_t>(reported) + static_cast<std::uint64_t>(rejected);
  return wrap_delta(0, static_cast<std::int64_t>(sum), bits);
}

// kCounterBitsMin, kCounterBitsMax: the counter widths the loop handles (the config reader
// checks against the same numbers).
inline constexpr int kCounterBitsMin = 16;
inline constexpr int kCounterBitsMax = 64;

// check_counter_bits: validates a counter width, naming the allowed range on failure.
Status check_counter_bits(int bits);

// normalise_reading: validates that `raw` is a legal reading of a `bits`-wide counter, either
// unsigned [0, 2^bits) or signed [-2^(bits-1), 2^(bits-1)), and returns it sign-extended.
Result<std::int64_t> normalise_reading(std::int64_t raw, int bits);

}  // namespace odo
