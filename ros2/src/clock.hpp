// now_ns: the bridge's clock reads (the time stamps' offset, write ages, the due-tick poll).
#pragma once

#include <time.h>

#include "odo/hal/time.hpp"

namespace odo::ros2 {

// now_ns: clock `id` now [ns].
inline TimeNs now_ns(clockid_t id) noexcept {
  timespec ts{};
  clock_gettime(id, &ts);
  return static_cast<TimeNs>(ts.tv_sec) * kNsPerSecond + ts.tv_nsec;
}

}  // namespace odo::ros2
