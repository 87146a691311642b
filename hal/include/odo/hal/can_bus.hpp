// CanBus: one endpoint on a classic CAN bus (8-byte frames). One implementation is a SocketCAN
// raw socket (drivers/), another a simulated bus port with fault injection (sim_hal/).
#pragma once

#include <array>
#include <cstdint>

#include "odo/hal/time.hpp"

namespace odo {

// CanFrame: one classic CAN frame. id is 11 bits (extended false) or 29 bits (extended true).
struct CanFrame {
  std::uint32_t id = 0;
  bool extended = false;
  bool rtr = false;      // remote transmission request: carries no data, len = requested DLC
  std::uint8_t len = 0;  // data length 0..8 [bytes]
  std::array<std::uint8_t, 8> data{};
  TimeNs stamp = 0;  // receive time on the loop's clock [ns]; 0 for frames to send
};

// CanTx: what became of one send(); anything but kSent means the frame was dropped.
enum class CanTx : std::uint8_t {
  kSent,       // handed to the controller's transmit queue
  kQueueFull,  // transmit queue full (ENOBUFS / EAGAIN): dropped, not retried
  kLinkDown,   // interface down or gone (ENETDOWN, ENXIO, ENODEV): dropped
  kError,      // any other failure: dropped
};

class CanBus {
 public:
  virtual ~CanBus() = default;
  // send: queues one frame without ever blocking; the result says whether it was dropped.
  virtual CanTx send(const CanFrame& f) noexcept = 0;
  // receive: takes the oldest received frame without blocking (every field of `out` written);
  // false when none is waiting (`out` then unspecified).
  virtual bool receive(CanFrame& out) noexcept = 0;
};

}  // namespace odo
