// SocketCanBus: a CanBus on a Linux SocketCAN interface (can0, vcan0, ...) through a raw socket
// (PF_CAN, SOCK_RAW, CAN_RAW). Non-blocking both ways: a full transmit queue (ENOBUFS, EAGAIN)
// or a link that is down drops the frame and says so; when the link comes back, sending resumes
// by itself (an interface that vanished is re-opened by name, at most once per retry period).
// Receive filters are installed in the kernel (CAN_RAW_FILTER), so frames the firmware does not
// want never reach user space. Linux types stay in the .cpp.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "odo/hal/can_bus.hpp"
#include "odo/hal/result.hpp"
#include "odo/hal/time.hpp"

namespace odo::drivers {

// CanFilter: a frame is received when (frame id & mask) == (id & mask) and the frame's
// extended flag equals `extended` (as CAN_RAW_FILTER with CAN_EFF_FLAG in the mask).
struct CanFilter {
  std::uint32_t id = 0;
  std::uint32_t mask = 0x7FF;
  bool extended = false;
};

struct SocketCanOptions {
  std::string interface = "can0";
  // Receive filters; empty = receive nothing (a transmit-only socket).
  std::vector<CanFilter> filters;
  bool receive_own = false;    // also receive frames this socket sent (tests)
  double reopen_period = 1.0;  // [s] between attempts to re-open a vanished interface
  int rx_buffer_bytes = 0;     // SO_RCVBUF, 0 = kernel default
  int tx_buffer_bytes = 0;     // SO_SNDBUF, 0 = kernel default (small: EAGAIN sooner, tests)
};

// tx_result_for_errno: how a failed write() of a frame is reported (ENOBUFS/EAGAIN queue full,
// ENETDOWN/ENXIO/ENODEV link down, anything else an error). Pure; unit-tested.
CanTx tx_result_for_errno(int err) noexcept;
// errno_means_vanished: true for the errno values after which the socket is re-opened by name
// (ENODEV, ENXIO: the interface was removed or re-created with a new index).
bool errno_means_vanished(int err) noexcept;
// to_socketcan_id: the Linux can_id word of a frame (CAN_EFF_FLAG set for extended ids; the id
// masked to 11 or 29 bits).
std::uint32_t to_socketcan_id(const CanFrame& f) noexcept;
// from_socketcan_id: fills f.id and f.extended from a Linux can_id word; false for remote (RTR)
// and error frames, which the firmware does not use.
bool from_socketcan_id(std::uint32_t can_id, CanFrame& f) noexcept;

// kernel_stamp_to_monotonic: a kernel receive stamp `kernel_rt` on CLOCK_REALTIME [ns] moved
// onto CLOCK_MONOTONIC, given both clocks read together just after (`rt_now`, `mono_now`): the
// frame's age on the realtime clock is subtracted from the monotonic now. An age below 0 (the
// realtime clock stepped back meanwhile) counts as 0, one above 10 s (stepped forward) too:
// then the read time is the best stamp there is. Pure; unit-tested.
TimeNs kernel_stamp_to_monotonic(TimeNs kernel_rt, TimeNs rt_now, TimeNs mono_now) noexcept;

// SocketCanCounters: cumulative since open; read from the thread that sends/receives.
struct SocketCanCounters {
  std::uint64_t sent = 0;
  std::uint64_t tx_queue_full = 0;  // dropped: ENOBUFS / EAGAIN
  std::uint64_t tx_link_down = 0;   // dropped: ENETDOWN / ENXIO / ENODEV
  std::uint64_t tx_errors = 0;      // dropped: any other errno
  std::uint64_t received = 0;
  std::uint64_t reopens = 0;  // successful re-opens after the interface vanished
};

class SocketCanBus final : public CanBus {
 public:
  ~SocketCanBus() override;
  // open: binds a raw socket to the named interface; errors name the interface and the errno.
  static Result<std::unique_ptr<SocketCanBus>> open(const SocketCanOptions& o);

  CanTx send(const CanFrame& f) noexcept override;
  // receive: the stamp is the kernel's receive time of the frame (SO_TIMESTAMPNS), moved onto
  // CLOCK_MONOTONIC [ns]; the read time when the kernel gave none.
  bool receive(CanFrame& out) noexcept override;

  const SocketCanCounters& counters() const noexcept { return counters_; }
  const std::string& interface() const noexcept { return opts_.interface; }
  // is_open: false while the interface has vanished and is waiting to be re-opened.
  bool is_open() const noexcept { return fd_ >= 0; }

 private:
  explicit SocketCanBus(SocketCanOptions o);
  // open_socket: a new bound raw socket for opts_ into fd_; returns 0 or the errno, and in
  // `stage` the call that failed. No allocation (it also runs on the loop thread to re-open).
  int open_socket(const char*& stage) noexcept;
  // try_reopen: at most once per reopen_period, replaces a closed/vanished socket; true if open.
  bool try_reopen() noexcept;
  void close_socket() noexcept;
  // close_and_retry_later: the interface vanished (or came back with a new index): closes the
  // socket; try_reopen re-opens it by name one reopen_period from now.
  void close_and_retry_later() noexcept;

  SocketCanOptions opts_;
  std::vector<std::uint32_t> kfilters_;  // struct can_filter pairs (can_id, can_mask), built once
  int fd_ = -1;
  TimeNs next_reopen_ = 0;  // CLOCK_MONOTONIC [ns]: no re-open attempt before it
  SocketCanCounters counters_;
};

}  // namespace odo::drivers
