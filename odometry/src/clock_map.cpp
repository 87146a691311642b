#include "odo/odometry/clock_map.hpp"

#include <algorithm>
#include <cmath>

namespace odo {

ClockMap::ClockMap(TimeNs window, std::size_t windows) noexcept
    : window_(window > 0 ? window : 1),
      windows_(std::clamp<std::size_t>(windows, 2, kMaxWindows)) {}

void ClockMap::reset() noexcept {
  head_ = count_ = 0;
  started_ = false;
}

double ClockMap::drift() const noexcept {
  if (count_ < 2) return 0.0;
  const Point& a = ring_[head_];
  const Point& b = ring_[(head_ + count_ - 1) % kMaxWindows];
  if (b.controller == a.controller) return 0.0;
  return static_cast<double>(b.offset - a.offset) /
         static_cast<double>(b.controller - a.controller);
}

TimeNs ClockMap::map(std::int64_t controller, TimeNs host_arrival) noexcept {
  const Point p{controller, host_arrival - controller};
  if (!started_) {
    started_ = true;
    window_start_ = controller;
    current_ = p;
  } else if (controller - window_start_ >= window_) {
    // Close the window: its minimum joins the ring (the oldest leaves when it is full).
    if (count_ == windows_) {
      head_ = (head_ + 1) % kMaxWindows;
      --count_;
    }
    ring_[(head_ + count_) % kMaxWindows] = current_;
    ++count_;
    window_start_ = controller;
    current_ = p;
  } else if (p.offset <= current_.offset) {
    current_ = p;
  }
  // Base: the newest closed minimum (its window is complete); before the first, the open one.
  const Point& base = count_ > 0 ? ring_[(head_ + count_ - 1) % kMaxWindows] : current_;
  const double predicted = static_cast<double>(base.offset) +
                           drift() * static_cast<double>(controller - base.controller);
  // A sample faster than the envelope is proof the envelope is too high: it is never later
  // than its own arrival.
  const auto offset = std::min(static_cast<std::int64_t>(std::llround(predicted)), p.offset);
  return controller + offset;
}

}  // namespace odo
