// VirtualClock: simulated time that advances only when the loop sleeps, so simulations run as
// fast as the machine allows and are exactly repeatable.
#pragma once

#include "odo/hal/clock.hpp"

namespace odo::sim {

class VirtualClock final : public Clock {
 public:
  explicit VirtualClock(TimeNs start = 0) : now_(start) {}
  TimeNs now() noexcept override { return now_; }
  // sleep_until: jumps to the deadline (never backwards).
  void sleep_until(TimeNs deadline) noexcept override {
    if (deadline > now_) now_ = deadline;
  }
  // advance: lets simulated work take time, e.g. a slow bus read that overruns a deadline [ns].
  void advance(TimeNs dt) noexcept { now_ += dt; }

 private:
  TimeNs now_;
};

}  // namespace odo::sim
