// RegisterBus: 32-bit memory-mapped registers of a microcontroller's peripherals (issue 36). On the
// chip it is plain volatile access (board/), on the host a register model of the peripheral
// (sim_hal/), so one driver source is tested against the model and runs on the chip.
#pragma once

#include <cstdint>

namespace odo {

class RegisterBus {
 public:
  virtual ~RegisterBus() = default;
  // read: the 32-bit register at byte address `addr`.
  virtual std::uint32_t read(std::uint32_t addr) noexcept = 0;
  // write: `value` into the register at `addr`.
  virtual void write(std::uint32_t addr, std::uint32_t value) noexcept = 0;
};

}  // namespace odo
