// Chip bring-up and services of the board room: clock tree, watchdog, semihosting exit (QEMU),
// the start-up's heap lock.
#pragma once

#include <cstdint>

namespace odo::board {

// ClockInfo: what clock_init achieved.
struct ClockInfo {
  std::uint32_t sysclk_hz = 16000000;  // core clock [Hz]
  std::uint32_t apb1_hz = 16000000;    // APB1 peripheral clock [Hz] (USART2)
  std::uint32_t apb2_hz = 16000000;    // APB2 peripheral clock [Hz] (USART1)
  std::uint32_t tim_hz = 16000000;  // the loop clock's count rate: SysTick on the core clock [Hz]
  bool pll = false;                 // running from the PLL (else the 16 MHz HSI)
};

// clock_init: 168 MHz from the 8 MHz HSE through the PLL (APB1 42 MHz, APB2 84 MHz, 5 wait
// states); every ready flag is waited for a bounded time, and the chip stays on the HSI when one
// never comes (QEMU 7.2's netduinoplus2 has no RCC model; its SysTick counts at 168 MHz).
ClockInfo clock_init() noexcept;
// watchdog_start / watchdog_kick: the IWDG on the 32 kHz LSI with a timeout of `ms` [ms],
// 1..4095; kick reloads it (the loop's observer, every tick).
void watchdog_start(std::uint32_t ms) noexcept;
void watchdog_kick() noexcept;
// semihost_exit: ends a QEMU run with `code` (semihosting SYS_EXIT_EXTENDED); on a chip without
// a debugger it resets instead.
[[noreturn]] void semihost_exit(int code) noexcept;
// semihost_cmdline: the program's command line given to QEMU (-semihosting-config arg=...) into
// buf (NUL-terminated); false without semihosting.
bool semihost_cmdline(char* buf, std::uint32_t size) noexcept;
// lock_heap: from now on any allocation is a fault reported over the UART (after start-up).
void lock_heap() noexcept;
// heap_allocations: malloc calls so far (all of them before lock_heap).
std::uint32_t heap_allocations() noexcept;

}  // namespace odo::board
