#include "odo/odometry/count_delta.hpp"

#include <string>

namespace odo {

Status check_counter_bits(int bits) {
  if (bits >= kCounterBitsMin && bits <= kCounterBitsMax) return Ok{};
  return range_error(integer_range("counter_bits", bits, kCounterBitsMin, kCounterBitsMax));
}

Result<std::int64_t> normalise_reading(std::int64_t raw, int bits) {
  if (auto s = check_counter_bits(bits); !s) return std::move(s).error();
  if (bits == 64) return raw;
  const std::int64_t half = std::int64_t{1} << (bits - 1);
  // The largest unsigned reading is 2^bits - 1 = (half - 1) + half; written so that it does not
  // overflow for bits = 63 (2 * half would be 2^63; found by fuzz_replay).
  const std::int64_t max_unsigned = (half - 1) + half;
  if (raw < -half || raw > max_unsigned) {
    return make_error(Errc::kInvalidArgument,
                      "reading " + std::to_string(raw) + " does not fit a " + std::to_string(bits) +
                          "-bit counter (expected [" + std::to_string(-half) + ", " +
                          std::to_string(max_unsigned) + "])");
  }
  // Sign-extend: unsigned readings at or above 2^(bits-1) are negative in two's complement.
  return wrap_delta(0, raw, bits);
}

}  // namespace odo
