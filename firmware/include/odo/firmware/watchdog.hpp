// LoopWatchdog: systemd liveness for the daemon. A thread sends READY=1 once the loop has
// ticked, then WATCHDOG=1 every half watchdog interval, but only when the loop's tick counter
// advanced since the previous ping: a stalled loop stops the pings and systemd restarts it.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>

#include "odo/hal/time.hpp"

namespace odo::fw {

class LoopWatchdog {
 public:
  using Heartbeat = std::function<std::uint64_t()>;  // returns the loop's tick counter

  // from_environment: uses NOTIFY_SOCKET / WATCHDOG_USEC; disabled (start/stop do nothing)
  // when not started by systemd.
  static std::unique_ptr<LoopWatchdog> from_environment(Heartbeat heartbeat);
  // to_socket: an explicit socket address ("@name" for the abstract namespace) and watchdog
  // interval [ns] (0: READY/STOPPING only).
  static std::unique_ptr<LoopWatchdog> to_socket(const std::string& address, TimeNs interval,
                                                 Heartbeat heartbeat);
  ~LoopWatchdog();

  bool enabled() const noexcept;
  TimeNs interval() const noexcept;  // [ns]
  // start: starts the notifier thread.
  void start();
  // stop: sends STOPPING=1 and joins the thread.
  void stop();
  std::uint64_t pings() const noexcept { return pings_.load(); }    // WATCHDOG=1 sent
  std::uint64_t stalls() const noexcept { return stalls_.load(); }  // checks without progress

 private:
  struct Impl;
  explicit LoopWatchdog(std::unique_ptr<Impl> impl);
  void run();
  std::unique_ptr<Impl> impl_;
  std::atomic<std::uint64_t> pings_{0};
  std::atomic<std::uint64_t> stalls_{0};
};

}  // namespace odo::fw
