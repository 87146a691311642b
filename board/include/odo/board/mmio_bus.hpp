// MmioBus: the chip's own registers as a RegisterBus (volatile 32-bit access), for the drivers
// that are tested on the host against sim_hal's register models.
#pragma once

#include "odo/board/stm32f4.hpp"
#include "odo/hal/register_bus.hpp"

namespace odo::board {

class MmioBus final : public RegisterBus {
 public:
  std::uint32_t read(std::uint32_t addr) noexcept override { return reg(addr); }
  void write(std::uint32_t addr, std::uint32_t value) noexcept override { reg(addr) = value; }
};

}  // namespace odo::board
