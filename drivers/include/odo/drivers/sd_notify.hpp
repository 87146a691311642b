// SdNotifier: the systemd notification protocol (sd_notify(3)) over the NOTIFY_SOCKET datagram
// socket, without libsystemd: READY=1, WATCHDOG=1, STOPPING=1, STATUS=...
#pragma once

#include <string>
#include <string_view>

#include "odo/hal/time.hpp"

namespace odo::drivers {

class SdNotifier {
 public:
  SdNotifier() = default;  // disabled
  ~SdNotifier();
  SdNotifier(SdNotifier&& o) noexcept;
  SdNotifier& operator=(SdNotifier&& o) noexcept;
  SdNotifier(const SdNotifier&) = delete;
  SdNotifier& operator=(const SdNotifier&) = delete;

  // from_environment: NOTIFY_SOCKET (path, or @abstract) and WATCHDOG_USEC/WATCHDOG_PID as set
  // by systemd; disabled when NOTIFY_SOCKET is unset or the socket cannot be created.
  static SdNotifier from_environment();
  // to_socket: a notifier for an explicit socket address (tests); watchdog interval [ns].
  static SdNotifier to_socket(std::string_view address, TimeNs watchdog_interval);

  bool enabled() const noexcept { return fd_ >= 0; }
  // watchdog_interval: WatchdogSec of the unit [ns]; 0 when no watchdog is requested.
  TimeNs watchdog_interval() const noexcept { return watchdog_; }
  // notify: sends one message, e.g. "READY=1"; false (nothing else happens) when disabled or
  // the send failed.
  bool notify(std::string_view message) const noexcept;

 private:
  int fd_ = -1;
  std::string address_;  // abstract addresses start with '\0'
  TimeNs watchdog_ = 0;
};

}  // namespace odo::drivers
