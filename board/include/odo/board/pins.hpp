// The board's pin map (README "On a real STM32F405 board"): USART1 PA9/PA10, USART2 PA2/PA3
// (AF7), left encoder TIM3 PA6/PA7, right encoder TIM4 PB6/PB7 (AF2).
#pragma once

namespace odo::board {

// pins_init: GPIOA/GPIOB clocks on, the pins above to their alternate functions, pulled up.
void pins_init() noexcept;

}  // namespace odo::board
