#include "odo/board/pins.hpp"

#include "odo/board/board_config.hpp"
#include "odo/board/stm32f4.hpp"

namespace odo::board {

namespace {

constexpr std::uintptr_t kGpioA = 0x40020000, kGpioB = 0x40020400, kGpioC = 0x40020800;
constexpr std::uintptr_t kModer = 0x00, kPupdr = 0x0C, kAfrl = 0x20, kAfrh = 0x24;

// alternate: pin `pin` of the port at `port` to alternate function `af`, with a pull-up (an
// unconnected encoder or RX line then reads high instead of floating).
void alternate(std::uintptr_t port, int pin, std::uint32_t af) noexcept {
  reg(port + kModer) = (reg(port + kModer) & ~(3u << (2 * pin))) | (2u << (2 * pin));
  reg(port + kPupdr) = (reg(port + kPupdr) & ~(3u << (2 * pin))) | (1u << (2 * pin));
  const std::uintptr_t afr = port + (pin < 8 ? kAfrl : kAfrh);
  const int shift = 4 * (pin % 8);
  reg(afr) = (reg(afr) & ~(0xFu << shift)) | (af << shift);
}

}  // namespace

void pins_init() noexcept {
  reg(rcc::kAhb1Enr) |= (1u << 0) | (1u << 1);  // GPIOA, GPIOB
  alternate(kGpioA, 9, 7);                      // USART1 TX
  alternate(kGpioA, 10, 7);                     // USART1 RX
  alternate(kGpioA, 2, 7);                      // USART2 TX
  alternate(kGpioA, 3, 7);                      // USART2 RX
  alternate(kGpioA, 6, 2);                      // TIM3 CH1: left encoder A
  alternate(kGpioA, 7, 2);                      // TIM3 CH2: left encoder B
  alternate(kGpioB, 6, 2);                      // TIM4 CH1: right encoder A
  alternate(kGpioB, 7, 2);                      // TIM4 CH2: right encoder B
  alternate(kGpioB, 8, 9);                      // CAN1 RX (pulled up: recessive when unwired)
  alternate(kGpioB, 9, 9);                      // CAN1 TX
  if (kBoardWheelsPerSide > 1) {                // the second wheel of each side (Stm32SideTimers)
    reg(rcc::kAhb1Enr) |= 1u << 2;              // GPIOC
    alternate(kGpioA, 0, 2);                    // TIM5 CH1: left wheel 2 A
    alternate(kGpioA, 1, 2);                    // TIM5 CH2: left wheel 2 B
    alternate(kGpioC, 6, 3);                    // TIM8 CH1: right wheel 2 A
    alternate(kGpioC, 7, 3);                    // TIM8 CH2: right wheel 2 B
  }
}

}  // namespace odo::board
