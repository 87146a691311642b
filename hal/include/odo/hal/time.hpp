// Time on the loop path: signed 64-bit nanoseconds of CLOCK_MONOTONIC (or of a virtual clock).
#pragma once

#include <cstdint>

namespace odo {

using TimeNs = std::int64_t;  // nanoseconds since an arbitrary epoch of the clock in use

inline constexpr TimeNs kNsPerSecond = 1'000'000'000;

// to_seconds: nanoseconds -> seconds.
constexpr double to_seconds(TimeNs ns) {
  return static_cast<double>(ns) * 1e-9;
}

// from_seconds: seconds -> nanoseconds, rounded to nearest.
constexpr TimeNs from_seconds(double s) {
  return static_cast<TimeNs>(s * 1e9 + (s >= 0 ? 0.5 : -0.5));
}

}  // namespace odo
