#include "odo/drivers/socketcan_bus.hpp"

#include <fcntl.h>
#include <linux/can.h>
#include <linux/can/raw.h>
#include <net/if.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "odo/drivers/monotonic_clock.hpp"

namespace odo::drivers {
namespace {

static_assert(sizeof(can_filter) == 2 * sizeof(std::uint32_t), "can_filter is two canid_t");

// receive_stamp: the kernel's stamp in `msg` on CLOCK_MONOTONIC, or now without one.
TimeNs receive_stamp(msghdr& msg) noexcept {
  const TimeNs mono = monotonic_now();
  for (cmsghdr* c = CMSG_FIRSTHDR(&msg); c != nullptr; c = CMSG_NXTHDR(&msg, c)) {
    if (c->cmsg_level != SOL_SOCKET || c->cmsg_type != SCM_TIMESTAMPNS) continue;
    timespec k{};
    std::memcpy(&k, CMSG_DATA(c), sizeof k);
    timespec rt{};
    ::clock_gettime(CLOCK_REALTIME, &rt);
    auto ns = [](const timespec& t) { return TimeNs{t.tv_sec} * kNsPerSecond + t.tv_nsec; };
    return kernel_stamp_to_monotonic(ns(k), ns(rt), mono);
  }
  return mono;
}

}  // namespace

CanTx tx_result_for_errno(int err) noexcept {
  switch (err) {
    case ENOBUFS:
    case EAGAIN:
      return CanTx::kQueueFull;
    case ENETDOWN:
    case ENXIO:
    case ENODEV:
      return CanTx::kLinkDown;
    default:
      return CanTx::kError;
  }
}

bool errno_means_vanished(int err) noexcept {
  return err == ENODEV || err == ENXIO;
}

std::uint32_t to_socketcan_id(const CanFrame& f) noexcept {
  const std::uint32_t rtr = f.rtr ? CAN_RTR_FLAG : 0u;  // a remote request (no data)
  return rtr | (f.extended ? ((f.id & CAN_EFF_MASK) | CAN_EFF_FLAG) : (f.id & CAN_SFF_MASK));
}

bool from_socketcan_id(std::uint32_t can_id, CanFrame& f) noexcept {
  if ((can_id & (CAN_RTR_FLAG | CAN_ERR_FLAG)) != 0) return false;
  f.extended = (can_id & CAN_EFF_FLAG) != 0;
  f.rtr = false;  // remote requests never get here (filtered above and in the kernel)
  f.id = f.extended ? (can_id & CAN_EFF_MASK) : (can_id & CAN_SFF_MASK);
  return true;
}

TimeNs kernel_stamp_to_monotonic(TimeNs kernel_rt, TimeNs rt_now, TimeNs mono_now) noexcept {
  constexpr TimeNs kMaxAge = 10 * kNsPerSecond;
  const TimeNs age = rt_now - kernel_rt;
  return age > 0 && age <= kMaxAge ? mono_now - age : mono_now;
}

SocketCanBus::SocketCanBus(SocketCanOptions o) : opts_(std::move(o)) {
  kfilters_.reserve(2 * opts_.filters.size());
  for (const CanFilter& cf : opts_.filters) {
    const std::uint32_t id_bits = cf.extended ? CAN_EFF_MASK : CAN_SFF_MASK;
    kfilters_.push_back((cf.id & id_bits) | (cf.extended ? CAN_EFF_FLAG : 0u));
    // The mask always compares the EFF flag (standard and extended ids are never confused)
    // and never lets RTR frames through.
    kfilters_.push_back((cf.mask & id_bits) | CAN_EFF_FLAG | CAN_RTR_FLAG);
  }
}

SocketCanBus::~SocketCanBus() {
  close_socket();
}

void SocketCanBus::close_socket() noexcept {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
}

void SocketCanBus::close_and_retry_later() noexcept {
  close_socket();
  // Not at once: the interface may be in the middle of going away or being re-created (ip link
  // delete / add); a period later it is a new interface or still gone.
  next_reopen_ = monotonic_now() + from_seconds(opts_.reopen_period);
}

int SocketCanBus::open_socket(const char*& stage) noexcept {
  close_socket();
  stage = "socket(PF_CAN, SOCK_RAW, CAN_RAW)";
  const int fd = ::socket(PF_CAN, SOCK_RAW | SOCK_NONBLOCK | SOCK_CLOEXEC, CAN_RAW);
  if (fd < 0) return errno;
  auto fail = [&](const char* what) {
    const int e = errno;
    stage = what;
    ::close(fd);
    return e;
  };
  ifreq ifr{};
  if (opts_.interface.empty() || opts_.interface.size() >= IFNAMSIZ) {
    ::close(fd);
    stage = "interface name (1..15 characters)";
    return EINVAL;
  }
  std::memcpy(ifr.ifr_name, opts_.interface.c_str(), opts_.interface.size() + 1);
  if (::ioctl(fd, SIOCGIFINDEX, &ifr) < 0) return fail("SIOCGIFINDEX");
  // Kernel filters: zero filters = the socket receives nothing.
  const socklen_t flen = static_cast<socklen_t>(kfilters_.size() * sizeof(std::uint32_t));
  if (::setsockopt(fd, SOL_CAN_RAW, CAN_RAW_FILTER, kfilters_.empty() ? nullptr : kfilters_.data(),
                   flen) < 0)
    return fail("setsockopt(CAN_RAW_FILTER)");
  const int own = opts_.receive_own ? 1 : 0;
  if (::setsockopt(fd, SOL_CAN_RAW, CAN_RAW_RECV_OWN_MSGS, &own, sizeof own) < 0)
    return fail("setsockopt(CAN_RAW_RECV_OWN_MSGS)");
  // The kernel's receive time of each frame (issue 39): the jump check and the wheels' common
  // instant need when a frame arrived, not when the loop got round to reading it.
  const int on = 1;
  if (::setsockopt(fd, SOL_SOCKET, SO_TIMESTAMPNS, &on, sizeof on) < 0)
    return fail("setsockopt(SO_TIMESTAMPNS)");
  if (opts_.rx_buffer_bytes > 0 &&
      ::setsockopt(fd, SOL_SOCKET, SO_RCVBUF, &opts_.rx_buffer_bytes, sizeof(int)) < 0)
    return fail("setsockopt(SO_RCVBUF)");
  if (opts_.tx_buffer_bytes > 0 &&
      ::setsockopt(fd, SOL_SOCKET, SO_SNDBUF, &opts_.tx_buffer_bytes, sizeof(int)) < 0)
    return fail("setsockopt(SO_SNDBUF)");
  sockaddr_can addr{};
  addr.can_family = AF_CAN;
  addr.can_ifindex = ifr.ifr_ifindex;
  if (::bind(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) < 0) return fail("bind");
  fd_ = fd;
  return 0;
}

Result<std::unique_ptr<SocketCanBus>> SocketCanBus::open(const SocketCanOptions& o) {
  if (!(o.reopen_period > 0.0) || o.reopen_period > 3600.0)
    return make_error(Errc::kInvalidArgument, "socketcan: reopen_period must be in (0, 3600] s");
  std::unique_ptr<SocketCanBus> bus(new SocketCanBus(o));
  const char* stage = "";
  const int err = bus->open_socket(stage);
  if (err != 0) {
    const Errc code = (err == ENODEV || err == ENXIO)                   ? Errc::kNotFound
                      : (err == EAFNOSUPPORT || err == EPROTONOSUPPORT) ? Errc::kUnsupported
                                                                        : Errc::kIo;
    return make_error(code,
                      "socketcan " + o.interface + ": " + stage + " failed: " + std::strerror(err) +
                          (code == Errc::kUnsupported ? " (kernel without CAN support?)" : ""));
  }
  return bus;
}

bool SocketCanBus::try_reopen() noexcept {
  if (fd_ >= 0) return true;
  const TimeNs now = monotonic_now();
  if (now < next_reopen_) return false;
  // The next attempt is a period away whether this one succeeds or not: a link that flaps
  // costs at most one socket() + bind() per period on the loop thread.
  next_reopen_ = now + from_seconds(opts_.reopen_period);
  const char* stage = "";
  if (open_socket(stage) != 0) return false;
  ++counters_.reopens;
  return true;
}

CanTx SocketCanBus::send(const CanFrame& f) noexcept {
  if (fd_ < 0 && !try_reopen()) {
    ++counters_.tx_link_down;
    return CanTx::kLinkDown;
  }
  can_frame cf{};
  cf.can_id = to_socketcan_id(f);
  cf.can_dlc = f.len > 8 ? 8 : f.len;
  std::memcpy(cf.data, f.data.data(), cf.can_dlc);
  const ssize_t n = ::send(fd_, &cf, sizeof cf, MSG_DONTWAIT);
  if (n == static_cast<ssize_t>(sizeof cf)) {
    ++counters_.sent;
    return CanTx::kSent;
  }
  const int err = n < 0 ? errno : EIO;
  const CanTx r = tx_result_for_errno(err);
  switch (r) {
    case CanTx::kQueueFull:
      ++counters_.tx_queue_full;
      break;
    case CanTx::kLinkDown:
      ++counters_.tx_link_down;
      if (errno_means_vanished(err)) close_and_retry_later();
      break;
    default:
      ++counters_.tx_errors;
      break;
  }
  return r;
}

bool SocketCanBus::receive(CanFrame& out) noexcept {
  if (fd_ < 0 && !try_reopen()) return false;
  for (;;) {
    can_frame cf{};
    iovec iov{&cf, sizeof cf};
    alignas(cmsghdr) std::uint8_t control[CMSG_SPACE(sizeof(timespec))];
    msghdr msg{};
    msg.msg_iov = &iov;
    msg.msg_iovlen = 1;
    msg.msg_control = control;
    msg.msg_controllen = sizeof control;
    const ssize_t n = ::recvmsg(fd_, &msg, MSG_DONTWAIT);
    if (n < 0) {
      // EAGAIN: nothing waiting. ENETDOWN is reported once after the link went down;
      // ENODEV after the interface vanished: re-open later.
      if (errno_means_vanished(errno)) close_and_retry_later();
      return false;
    }
    if (n != static_cast<ssize_t>(sizeof cf)) continue;  // not a classic frame (CAN FD): skip
    if (!from_socketcan_id(cf.can_id, out)) continue;
    out.len = cf.can_dlc > 8 ? 8 : cf.can_dlc;
    out.data = {};
    std::memcpy(out.data.data(), cf.data, out.len);
    out.stamp = receive_stamp(msg);
    ++counters_.received;
    return true;
  }
}

}  // namespace odo::drivers
