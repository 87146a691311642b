// Clock: the time base of the loop. Real targets use CLOCK_MONOTONIC; simulations a virtual clock.
#pragma once

#include "odo/hal/time.hpp"

namespace odo {

class Clock {
 public:
  virtual ~Clock() = default;
  // now: current time of this clock [ns]; monotonic, never jumps backwards.
  virtual TimeNs now() noexcept = 0;
  // sleep_until: block until now() >= deadline [ns]; returns at once if it already passed.
  virtual void sleep_until(TimeNs deadline) noexcept = 0;
};

}  // namespace odo
