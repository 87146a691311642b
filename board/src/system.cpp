#include "odo/board/system.hpp"

#include <cstddef>
#include <cstdlib>

#include "odo/board/board_config.hpp"
#include "odo/board/fault.hpp"
#include "odo/board/stm32f4.hpp"

namespace odo::board {

namespace {

// wait_bit: polls until (reg & mask) == want, at most `tries` times.
bool wait_bit(std::uintptr_t r, std::uint32_t mask, std::uint32_t want, int tries) noexcept {
  for (int i = 0; i < tries; ++i) {
    if ((reg(r) & mask) == want) return true;
  }
  return false;
}

// semihost: one semihosting call (ARM: bkpt 0xAB, operation in r0, argument block in r1).
int semihost(int op, const void* arg) noexcept {
  register int r0 asm("r0") = op;
  register const void* r1 asm("r1") = arg;
  asm volatile("bkpt 0xAB" : "+r"(r0) : "r"(r1) : "memory");
  return r0;
}

std::uint32_t g_allocations = 0;
bool g_heap_locked = false;

}  // namespace

ClockInfo clock_init() noexcept {
  ClockInfo info;
  reg(rcc::kApb1Enr) |= (1u << 1) | (1u << 2) | (1u << 17) | (1u << 28);  // TIM3/4, USART2, PWR
  reg(rcc::kApb2Enr) |= 1u << 4;                                          // USART1
  if (kBoardWheelsPerSide > 1) {  // the second wheel of each side: TIM5 (APB1), TIM8 (APB2)
    reg(rcc::kApb1Enr) |= 1u << 3;
    reg(rcc::kApb2Enr) |= 1u << 1;
  }
  reg(rcc::kCr) |= 1u << 16;                              // HSEON
  if (!wait_bit(rcc::kCr, 1u << 17, 1u << 17, 100000)) {  // HSERDY
    // No crystal, or QEMU (no RCC model): its SysTick counts at 168 MHz whatever RCC says.
    if (ODO_BOARD_QEMU) info.tim_hz = 168000000u;
    return info;
  }
  // PLL: 8 MHz / M 8 * N 336 / P 2 = 168 MHz, Q 7 (48 MHz), source HSE.
  reg(rcc::kPllCfgr) = 8u | (336u << 6) | (0u << 16) | (1u << 22) | (7u << 24);
  reg(rcc::kCr) |= 1u << 24;  // PLLON
  if (!wait_bit(rcc::kCr, 1u << 25, 1u << 25, 100000)) return info;
  reg(flash_if::kAcr) = 5u | (1u << 8) | (1u << 9) | (1u << 10);  // 5 WS, prefetch, I/D cache
  // AHB /1, APB1 /4 (42 MHz), APB2 /2 (84 MHz), system clock = PLL.
  reg(rcc::kCfgr) = (0u << 4) | (5u << 10) | (4u << 13) | 2u;
  if (!wait_bit(rcc::kCfgr, 0xCu, 0x8u, 100000)) return info;
  info = ClockInfo{168000000, 42000000, 84000000, 168000000, true};
  return info;
}

void watchdog_start(std::uint32_t ms) noexcept {
  reg(iwdg::kKr) = iwdg::kKeyUnlock;
  reg(iwdg::kPr) = 3;  // LSI 32 kHz / 32 = 1 kHz: one count a millisecond
  reg(iwdg::kRlr) = ms > 4095 ? 4095 : (ms == 0 ? 1 : ms);
  reg(iwdg::kKr) = iwdg::kKeyRefresh;
  reg(iwdg::kKr) = iwdg::kKeyStart;
}

void watchdog_kick() noexcept {
  reg(iwdg::kKr) = iwdg::kKeyRefresh;
}

void semihost_exit(int code) noexcept {
  if (ODO_BOARD_QEMU) {
    // SYS_EXIT_EXTENDED (0x20): ADP_Stopped_ApplicationExit with the exit code.
    const std::uint32_t block[2] = {0x20026u, static_cast<std::uint32_t>(code)};
    semihost(0x20, block);
  }
  reg(scb::kAircr) = (0x5FAu << 16) | (1u << 2);  // SYSRESETREQ
  for (;;) {
  }
}

bool semihost_cmdline(char* buf, std::uint32_t size) noexcept {
  if (!ODO_BOARD_QEMU || size == 0) return false;
  std::uint32_t block[2] = {reinterpret_cast<std::uint32_t>(buf), size};
  buf[0] = '\0';
  return semihost(0x15, block) == 0;  // SYS_GET_CMDLINE
}

void lock_heap() noexcept {
  g_heap_locked = true;
}

std::uint32_t heap_allocations() noexcept {
  return g_allocations;
}

}  // namespace odo::board

// The linker wraps malloc (-Wl,--wrap=malloc): every allocation is counted, and one after
// start-up (the loop running) is a fault: "no heap after start-up" is checked, not hoped for.
extern "C" void* __real_malloc(std::size_t n);
extern "C" void* __wrap_malloc(std::size_t n) {
  if (odo::board::g_heap_locked) odo::board::report_fatal("heap allocation after start-up", n);
  ++odo::board::g_allocations;
  return __real_malloc(n);
}

// picolibc's exit() ends here: QEMU exits with the code, a chip resets.
extern "C" [[noreturn]] void _exit(int code) {
  odo::board::semihost_exit(code);
}
