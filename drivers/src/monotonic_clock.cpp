#include "odo/drivers/monotonic_clock.hpp"

#include <time.h>

#include <cerrno>

namespace odo::drivers {

TimeNs monotonic_now() noexcept {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<TimeNs>(ts.tv_sec) * kNsPerSecond + ts.tv_nsec;
}

TimeNs MonotonicClock::now() noexcept {
  return monotonic_now();
}

void MonotonicClock::sleep_until(TimeNs deadline) noexcept {
  timespec ts{};
  ts.tv_sec = static_cast<time_t>(deadline / kNsPerSecond);
  ts.tv_nsec = static_cast<long>(deadline % kNsPerSecond);
  // clock_nanosleep returns the error number directly; EINTR from a signal (SIGHUP, SIGTERM)
  // just resumes: the caller checks its stop flag after the tick.
  while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) == EINTR) {
  }
}

}  // namespace odo::drivers
