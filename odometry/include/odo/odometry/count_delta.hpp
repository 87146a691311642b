// Wrap-aware differences of two's-complement hardware counters of 16 to 64 bits.
#pragma once

#include <cstdint>

#include "odo/hal/encoder.hpp"
#include "odo/hal/result.hpp"

namespace odo {

// wrap_delta: hal/encoder.hpp (the counters' own arithmetic; backends use it too).

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
