// MonotonicClock: CLOCK_MONOTONIC with absolute-deadline sleeps (clock_nanosleep TIMER_ABSTIME),
// so wall-clock jumps (NTP, date) never move the loop.
#pragma once

#include "odo/hal/clock.hpp"

namespace odo::drivers {

// monotonic_now: CLOCK_MONOTONIC now [ns]; the drivers' time stamps are on this clock.
TimeNs monotonic_now() noexcept;

class MonotonicClock final : public Clock {
 public:
  TimeNs now() noexcept override;
  // sleep_until: sleeps to an absolute deadline; restarts after signals (EINTR).
  void sleep_until(TimeNs deadline) noexcept override;
};

}  // namespace odo::drivers
