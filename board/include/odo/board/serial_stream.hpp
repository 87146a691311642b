// SerialStream: the serial counts stream (protocol/serial_counts.hpp, issue 37) on a UART: a tick
// observer that sends the raw wheel counters every `div`-th tick (20 bytes a record: at 115200
// baud at most 576 records/s; default 100 Hz), so a Linux host's serial backend can take this
// firmware as its counter peer.
#pragma once

#include <cstdint>

#include "odo/board/uart.hpp"
#include "odo/loop/loop.hpp"

namespace odo::board {

class SerialStream final : public loop::TickObserver {
 public:
  // SerialStream: records of `lp`'s last reading to `uart` every `div` ticks (0: off).
  SerialStream(const loop::OdometryLoop& lp, Uart& uart, std::uint32_t div) noexcept
      : loop_(&lp), uart_(&uart), div_(div) {}
  void on_tick(const loop::LoopSnapshot& s) noexcept override;
  std::uint32_t sent() const noexcept { return sent_; }

 private:
  const loop::OdometryLoop* loop_;
  Uart* uart_;
  std::uint32_t div_;
  std::uint16_t seq_ = 0;
  std::uint32_t sent_ = 0;
};

}  // namespace odo::board
