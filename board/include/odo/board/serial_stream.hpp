// SerialStream: the serial counts stream (protocol/serial_counts.hpp, issue 37) on a UART: a tick
// observer that sends the raw wheel counters every `div`-th tick (20 bytes a record: at 115200
// baud at most 576 records/s; default 100 Hz), so a Linux host's serial backend can take this
// firmware as its counter peer. One wheel per side: version 1 records (what every host reads).
// Several wheels per side (issue 38): version 2 records, every wheel's own counter and its
// fault bit (12 + 8 N bytes + COBS and delimiter: 30 bytes with N = 2, 384 records/s at 115200);
// the host combines each side's wheels itself (odometryd's [encoder] wheels_per_side = N).
#pragma once

#include <array>
#include <cstdint>

#include "odo/board/uart.hpp"
#include "odo/hal/side_wheels.hpp"
#include "odo/loop/loop.hpp"
#include "odo/protocol/serial_counts.hpp"

namespace odo::board {

class SerialStream final : public loop::TickObserver {
 public:
  // SerialStream: records of `lp`'s last reading to `uart` every `div` ticks (0: off); with
  // `wheels` (the readings of the sample the loop last read, [0] left, [1] right) and
  // wheels_per_side 2..4, version 2 records of those wheels.
  SerialStream(const loop::OdometryLoop& lp, Uart& uart, std::uint32_t div,
               const std::array<SideReadings, 2>* wheels = nullptr,
               int wheels_per_side = 1) noexcept
      : loop_(&lp), uart_(&uart), div_(div), wheels_(wheels), n_(wheels ? wheels_per_side : 1) {}
  void on_tick(const loop::LoopSnapshot& s) noexcept override;
  std::uint32_t sent() const noexcept { return sent_; }

 private:
  // send_wheels: the version 2 record of `c` with the wheels' counters and faults.
  bool send_wheels(protocol::SerialCounts& c) noexcept;

  const loop::OdometryLoop* loop_;
  Uart* uart_;
  std::uint32_t div_;
  const std::array<SideReadings, 2>* wheels_;
  int n_;  // wheels per side
  std::uint16_t seq_ = 0;
  std::uint32_t sent_ = 0;
};

}  // namespace odo::board
