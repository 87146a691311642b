// BxCan: the STM32F4's bxCAN controller (CAN1, RM0090 32) at register level as a CanBus: three
// transmit mailboxes (a send takes an empty one, none empty: kQueueFull), receive FIFO 0 behind
// one 32-bit identifier-mask filter in bank 0 (standard ids), and bit timing from BTR. Register
// access through a RegisterBus: MmioBus on the chip, sim::BxCanModel on the host.
#pragma once

#include <cstdint>

#include "odo/hal/can_bus.hpp"
#include "odo/hal/register_bus.hpp"
#include "odo/hal/result.hpp"

namespace odo::board {

class BxCan final : public CanBus {
 public:
  static constexpr std::uint32_t kBase = 0x40006400;
  // kBtr500k: 500 kbit/s from APB1 42 MHz: prescaler 6 (BRP 5), 1 + 11 + 2 = 14 quanta, sample
  // point 85.7 %, SJW 1.
  static constexpr std::uint32_t kBtr500k = (1u << 20) | (10u << 16) | 5u;

  explicit BxCan(RegisterBus& bus) noexcept : bus_(&bus) {}
  // init: initialisation mode, bit timing `btr`, automatic bus-off recovery and retransmission,
  // filter bank 0 accepting standard ids with (id & mask) == (accept & mask) into FIFO 0, then
  // normal mode. Errors: the controller does not enter or leave initialisation mode.
  Status init(std::uint32_t btr, std::uint32_t accept, std::uint32_t mask) noexcept;
  CanTx send(const CanFrame& f) noexcept override;
  bool receive(CanFrame& out) noexcept override;

 private:
  Status wait_inak(bool set) noexcept;
  RegisterBus* bus_;
};

}  // namespace odo::board
