// STM32F405 registers the board room uses (RM0090 and the Cortex-M4 architecture), addresses
// only: every access goes through reg(), one volatile 32-bit word.
#pragma once

#include <cstdint>

namespace odo::board {

// reg: the 32-bit memory-mapped register at `addr`.
inline volatile std::uint32_t& reg(std::uintptr_t addr) noexcept {
  return *reinterpret_cast<volatile std::uint32_t*>(addr);
}

namespace rcc {  // RM0090 6.3
inline constexpr std::uintptr_t kBase = 0x40023800;
inline constexpr std::uintptr_t kCr = kBase + 0x00, kPllCfgr = kBase + 0x04, kCfgr = kBase + 0x08;
inline constexpr std::uintptr_t kAhb1Enr = kBase + 0x30, kApb1Enr = kBase + 0x40;
inline constexpr std::uintptr_t kApb2Enr = kBase + 0x44, kCsr = kBase + 0x74;
}  // namespace rcc

namespace flash_if {  // RM0090 3.9: the flash interface's access control (wait states)
inline constexpr std::uintptr_t kAcr = 0x40023C00;
}

namespace usart {  // RM0090 30.6: SR, DR, BRR, CR1 of USART1 (APB2) and USART2 (APB1)
inline constexpr std::uintptr_t kUsart1 = 0x40011000, kUsart2 = 0x40004400;
inline constexpr std::uintptr_t kSr = 0x00, kDr = 0x04, kBrr = 0x08, kCr1 = 0x0C;
inline constexpr std::uint32_t kSrRxne = 1u << 5, kSrTxe = 1u << 7, kSrOre = 1u << 3;
inline constexpr std::uint32_t kCr1Ue = 1u << 13, kCr1Txeie = 1u << 7, kCr1Rxneie = 1u << 5;
inline constexpr std::uint32_t kCr1Te = 1u << 3, kCr1Re = 1u << 2;
}  // namespace usart

namespace tim {  // RM0090 18.4: general-purpose timer TIM2 (32-bit, APB1)
inline constexpr std::uintptr_t kTim2 = 0x40000000;
inline constexpr std::uintptr_t kCr1 = 0x00, kDier = 0x0C, kSr = 0x10, kEgr = 0x14, kCnt = 0x24;
inline constexpr std::uintptr_t kPsc = 0x28, kArr = 0x2C;
inline constexpr std::uint32_t kCr1Cen = 1u << 0, kDierUie = 1u << 0, kSrUif = 1u << 0;
}  // namespace tim

namespace iwdg {  // RM0090 21.4: independent watchdog on the 32 kHz LSI
inline constexpr std::uintptr_t kKr = 0x40003000, kPr = 0x40003004, kRlr = 0x40003008;
inline constexpr std::uint32_t kKeyStart = 0xCCCC, kKeyRefresh = 0xAAAA, kKeyUnlock = 0x5555;
}  // namespace iwdg

namespace scb {  // Cortex-M4: system control block and NVIC
inline constexpr std::uintptr_t kCpacr = 0xE000ED88, kAircr = 0xE000ED0C;
inline constexpr std::uintptr_t kShcsr = 0xE000ED24, kCfsr = 0xE000ED28, kHfsr = 0xE000ED2C;
inline constexpr std::uintptr_t kMmfar = 0xE000ED34, kBfar = 0xE000ED38;
inline constexpr std::uintptr_t kNvicIser = 0xE000E100, kNvicIpr = 0xE000E400;
}  // namespace scb

// Interrupt numbers (RM0090 table 61).
inline constexpr int kIrqTim2 = 28, kIrqUsart1 = 37, kIrqUsart2 = 38;
inline constexpr int kIrqCount = 82;

// nvic_enable: unmasks interrupt `irq` at priority `prio` (0 highest, 4 bits used).
inline void nvic_enable(int irq, std::uint8_t prio) noexcept {
  *reinterpret_cast<volatile std::uint8_t*>(scb::kNvicIpr + irq) =
      static_cast<std::uint8_t>(prio << 4);
  reg(scb::kNvicIser + 4 * (irq / 32)) = 1u << (irq % 32);
}

}  // namespace odo::board
