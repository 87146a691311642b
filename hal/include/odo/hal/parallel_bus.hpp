// ParallelBus: the 8-bit register bus of a peripheral chip such as the HCTL-1100 (multiplexed
// address/data lines AD0..AD7 plus ALE, CS, OE and R/W). One implementation drives GPIO lines
// through libgpiod (drivers/), another talks to a register model (sim_hal/).
#pragma once

#include <cstdint>

namespace odo {

// BusRead: the data byte of one read cycle; ok false when the bus could not be driven.
struct BusRead {
  std::uint8_t value = 0;
  bool ok = false;
};

class ParallelBus {
 public:
  virtual ~ParallelBus() = default;
  // read_register: one complete read cycle of register `reg` of the chip selected by `unit`
  // (0-based chip-select index); never blocks longer than one bus cycle.
  virtual BusRead read_register(int unit, std::uint8_t reg) noexcept = 0;
  // units: how many chips (chip-select lines) share this bus.
  virtual int units() const noexcept = 0;
};

}  // namespace odo
