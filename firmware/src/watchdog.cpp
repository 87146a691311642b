#include "odo/firmware/watchdog.hpp"

#include <chrono>
#include <condition_variable>
#include <mutex>
#include <string>
#include <thread>

#include "odo/drivers/sd_notify.hpp"

namespace odo::fw {

struct LoopWatchdog::Impl {
  drivers::SdNotifier notifier;
  Heartbeat heartbeat;
  std::thread thread;
  std::mutex m;
  std::condition_variable cv;
  bool stop = false;
};

LoopWatchdog::LoopWatchdog(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}

LoopWatchdog::~LoopWatchdog() {
  stop();
}

std::unique_ptr<LoopWatchdog> LoopWatchdog::from_environment(Heartbeat heartbeat) {
  auto impl = std::make_unique<Impl>();
  impl->notifier = drivers::SdNotifier::from_environment();
  impl->heartbeat = std::move(heartbeat);
  return std::unique_ptr<LoopWatchdog>(new LoopWatchdog(std::move(impl)));
}

std::unique_ptr<LoopWatchdog> LoopWatchdog::to_socket(const std::string& address, TimeNs interval,
                                                      Heartbeat heartbeat) {
  auto impl = std::make_unique<Impl>();
  impl->notifier = drivers::SdNotifier::to_socket(address, interval);
  impl->heartbeat = std::move(heartbeat);
  return std::unique_ptr<LoopWatchdog>(new LoopWatchdog(std::move(impl)));
}

bool LoopWatchdog::enabled() const noexcept {
  return impl_->notifier.enabled();
}

TimeNs LoopWatchdog::interval() const noexcept {
  return impl_->notifier.watchdog_interval();
}

void LoopWatchdog::start() {
  if (!enabled() || impl_->thread.joinable()) return;
  impl_->thread = std::thread([this] { run(); });
}

void LoopWatchdog::stop() {
  if (!impl_->thread.joinable()) return;
  {
    std::lock_guard lk(impl_->m);
    impl_->stop = true;
  }
  impl_->cv.notify_all();
  impl_->thread.join();
  impl_->notifier.notify("STOPPING=1");
}

void LoopWatchdog::run() {
  Impl& d = *impl_;
  const TimeNs wd = d.notifier.watchdog_interval();
  // Until the first tick: poll every 10 ms (or faster for very short watchdogs).
  TimeNs poll = 10'000'000;
  if (wd > 0 && wd / 4 < poll) poll = wd / 4;
  std::unique_lock lk(d.m);
  auto wait = [&](TimeNs ns) {
    return d.cv.wait_for(lk, std::chrono::nanoseconds(ns), [&] { return d.stop; });
  };
  std::uint64_t last = 0;
  while ((last = d.heartbeat()) == 0) {
    if (wait(poll)) return;
  }
  d.notifier.notify("READY=1\nSTATUS=loop running");
  if (wd <= 0) {
    while (!wait(1'000'000'000)) {
    }
    return;
  }
  bool stalled = false;
  while (!wait(wd / 2)) {
    const std::uint64_t now = d.heartbeat();
    if (now != last) {
      d.notifier.notify(stalled ? "WATCHDOG=1\nSTATUS=loop running" : "WATCHDOG=1");
      pings_.fetch_add(1);
      stalled = false;
      last = now;
    } else {
      // No ping: if the loop stays stuck for the whole interval, systemd restarts the service.
      stalls_.fetch_add(1);
      if (!stalled) d.notifier.notify("STATUS=loop stalled at tick " + std::to_string(now));
      stalled = true;
    }
  }
}

}  // namespace odo::fw
