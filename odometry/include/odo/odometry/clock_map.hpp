// ClockMap: a remote controller's clock mapped onto the host's, from the times at which its
// stamped samples arrive. Every arrival is at least the (unknown, constant) minimum transport
// delay after its stamp; spikes only ever add delay. So the lower envelope of the offset
// host_arrival - controller_time is the true offset plus the minimum delay: the minimum offset
// of each window of controller time is kept, the drift (rate difference of the two clocks) is
// the slope between the oldest and the newest of the last `windows` minima, and a sample maps
// to the newest minimum extrapolated with that drift, never later than its own arrival.
// Pure math: times are arguments, no I/O, no allocation.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

#include "odo/hal/time.hpp"

namespace odo {

class ClockMap {
 public:
  static constexpr std::size_t kMaxWindows = 16;

  // window: length of one minimum window of controller time [ns] (> 0); windows: how many
  // window minima span the drift estimate (2..kMaxWindows).
  ClockMap(TimeNs window, std::size_t windows) noexcept;

  // map: host time [ns] of a sample stamped `controller` [ns, unwrapped, increasing] that
  // arrived at `host_arrival` [ns]; updates the estimate with this sample.
  TimeNs map(std::int64_t controller, TimeNs host_arrival) noexcept;
  // reset: forget everything (the controller rebooted: its clock restarted).
  void reset() noexcept;
  // drift: the estimated rate difference host/controller - 1 [s/s] (0 until two windows).
  double drift() const noexcept;

 private:
  struct Point {
    std::int64_t controller = 0;  // [ns]
    std::int64_t offset = 0;      // host - controller [ns]
  };
  TimeNs window_;
  std::size_t windows_;
  std::array<Point, kMaxWindows> ring_{};  // closed windows' minima, oldest at head_
  std::size_t head_ = 0;
  std::size_t count_ = 0;
  Point current_{};                // the open window's minimum so far
  std::int64_t window_start_ = 0;  // controller time the open window began [ns]
  bool started_ = false;
};

}  // namespace odo
