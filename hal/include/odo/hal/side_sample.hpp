// Helpers of the backends that read several encoders per side (issue 38): how a wheel's number
// maps onto a backend's per-side configuration, and how one combined read fills the sample.
// The combiner itself is side_wheels.hpp.
#pragma once

#include <array>
#include <cstddef>

#include "odo/hal/encoder.hpp"
#include "odo/hal/side_wheels.hpp"

namespace odo {

// wheel_of_side: wheel `i` of a backend (side i % 2, 0 left; wheel i / 2 of that side, so 0 and
// 1 are the first wheels of the left and right side) from the per-side first entries and the
// arrays of the further wheels (more_*[k - 1] is wheel k).
template <class T, std::size_t M>
constexpr const T& wheel_of_side(int i, const T& left, const T& right,
                                 const std::array<T, M>& more_left,
                                 const std::array<T, M>& more_right) noexcept {
  const bool is_left = i % 2 == 0;
  const int k = i / 2;
  if (k <= 0) return is_left ? left : right;
  const auto m = static_cast<std::size_t>(k - 1);
  return is_left ? more_left[m] : more_right[m];
}

// apply_side_step: one combined read into the sample: the sides' counts [counts], the flags
// (slip, wheel-dropped, stale), the spreads and the combiner's event counters (its side stale
// events added to the backend's own).
inline void apply_side_step(const SideStep& step, const SideCounters& c,
                            EncoderSample& s) noexcept {
  s.left = step.left;
  s.right = step.right;
  s.flags |= step.flags;
  s.spread_left = step.spread_left;
  s.spread_right = step.spread_right;
  s.counters.slip_events = c.slip_events;
  s.counters.wheel_drops = c.wheel_drops;
  s.counters.stale_events += c.stale_events;
}

}  // namespace odo
