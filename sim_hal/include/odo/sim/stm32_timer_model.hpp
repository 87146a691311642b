// Stm32TimerModel: register model of STM32F4 general-purpose timers (RM0090 18.4) as quadrature
// counters in encoder mode, for the board's encoder driver on the host (issue 36). Each timer
// answers at its base address: CR1, SMCR, CCMR1, CCER, CNT, PSC, ARR. The counter moves only
// while CEN is set, SMS is an encoder mode and both channels are inputs mapped on TI1/TI2
// (CC1S = CC2S = 01), by one count per edge in mode 3 (x4) and wraps at ARR as the chip does (up
// past ARR to 0, down past 0 to ARR). Other registers read 0; writes to them are recorded.
#pragma once

#include <array>
#include <cstdint>

#include "odo/hal/register_bus.hpp"

namespace odo::sim {

class Stm32TimerModel final : public RegisterBus {
 public:
  static constexpr std::uint32_t kTim3 = 0x40000400, kTim4 = 0x40000800;
  static constexpr std::uint32_t kTim5 = 0x40000C00, kTim8 = 0x40010400;
  static constexpr std::uint32_t kCr1 = 0x00, kSmcr = 0x08, kCcmr1 = 0x18, kCcer = 0x20;
  static constexpr std::uint32_t kCnt = 0x24, kPsc = 0x28, kArr = 0x2C;

  std::uint32_t read(std::uint32_t addr) noexcept override;
  void write(std::uint32_t addr, std::uint32_t value) noexcept override;

  // edges: `n` quadrature edges on timer `unit` (0: TIM3, 1: TIM4, 2: TIM5, 3: TIM8), forward
  // n > 0, backward n < 0 (the A/B phase order); in encoder mode 3 each edge counts. Ignored
  // unless configured.
  void edges(int unit, std::int64_t n) noexcept;
  // counting: whether timer `unit` is configured to count its encoder (see above).
  bool counting(int unit) const noexcept;
  // unknown_writes: writes to registers or addresses the model does not have.
  int unknown_writes() const noexcept { return unknown_writes_; }

 private:
  // The registers in the order of the source's field table: CR1, SMCR, CCMR1, CCER, CNT, PSC, ARR.
  static constexpr std::size_t kCr1i = 0, kSmcri = 1, kCcmr1i = 2, kCnti = 4, kArri = 6;
  struct Timer {
    std::array<std::uint32_t, 7> regs{0, 0, 0, 0, 0, 0, 0xFFFF};  // ARR resets to 0xFFFF
  };
  // timer: the timer at `addr`'s base and the register offset; null for another address.
  Timer* timer(std::uint32_t addr, std::uint32_t& off) noexcept;
  // field: the register at `addr` and the bits a write keeps; null for one the model lacks.
  std::uint32_t* field(std::uint32_t addr, std::uint32_t& mask) noexcept;
  std::array<Timer, 4> t_{};
  int unknown_writes_ = 0;
};

}  // namespace odo::sim
