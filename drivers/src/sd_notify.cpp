#include "odo/drivers/sd_notify.hpp"

#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <cstddef>
#include <cstdlib>
#include <cstring>
#include <utility>

namespace odo::drivers {

SdNotifier::~SdNotifier() {
  if (fd_ >= 0) ::close(fd_);
}

SdNotifier::SdNotifier(SdNotifier&& o) noexcept
    : fd_(std::exchange(o.fd_, -1)), address_(std::move(o.address_)), watchdog_(o.watchdog_) {}

SdNotifier& SdNotifier::operator=(SdNotifier&& o) noexcept {
  if (this != &o) {
    if (fd_ >= 0) ::close(fd_);
    fd_ = std::exchange(o.fd_, -1);
    address_ = std::move(o.address_);
    watchdog_ = o.watchdog_;
  }
  return *this;
}

SdNotifier SdNotifier::to_socket(std::string_view address, TimeNs watchdog_interval) {
  SdNotifier n;
  if (address.empty() || address.size() >= sizeof(sockaddr_un::sun_path)) return n;
  n.address_ = std::string(address);
  if (n.address_[0] == '@') n.address_[0] = '\0';  // Linux abstract namespace
  n.fd_ = ::socket(AF_UNIX, SOCK_DGRAM | SOCK_CLOEXEC | SOCK_NONBLOCK, 0);
  n.watchdog_ = watchdog_interval;
  return n;
}

SdNotifier SdNotifier::from_environment() {
  const char* sock = std::getenv("NOTIFY_SOCKET");
  if (sock == nullptr) return {};
  TimeNs wd = 0;
  // WATCHDOG_PID, when set, names the process the watchdog is meant for (not a child).
  const char* pid = std::getenv("WATCHDOG_PID");
  const char* usec = std::getenv("WATCHDOG_USEC");
  if (usec != nullptr && (pid == nullptr || std::atoll(pid) == static_cast<long long>(::getpid())))
    wd = static_cast<TimeNs>(std::atoll(usec)) * 1000;
  if (wd < 0) wd = 0;
  return to_socket(sock, wd);
}

bool SdNotifier::notify(std::string_view message) const noexcept {
  // Non-blocking socket: a receiver that stopped reading (full queue) costs a lost message,
  // never a blocked notifier thread.
  if (fd_ < 0) return false;
  sockaddr_un sa{};
  sa.sun_family = AF_UNIX;
  std::memcpy(sa.sun_path, address_.data(), address_.size());
  const auto len = static_cast<socklen_t>(offsetof(sockaddr_un, sun_path) + address_.size());
  return ::sendto(fd_, message.data(), message.size(), MSG_NOSIGNAL,
                  reinterpret_cast<const sockaddr*>(&sa),
                  len) == static_cast<ssize_t>(message.size());
}

}  // namespace odo::drivers
