// Fault reports: a HardFault, MemManage, BusFault, UsageFault or an unexpected interrupt prints
// the exception number, the stacked registers (r0-r3, r12, lr, pc, xpsr) and the fault status
// registers (CFSR, HFSR, MMFAR, BFAR) on USART1 as one '#'-line (the SLCAN reader ignores it),
// then ends the run (QEMU: exit code 3) or resets the chip.
#pragma once

#include <cstdint>

namespace odo::board {

inline constexpr int kFaultExitCode = 3;

// report_fatal: `text` and a number as a '#'-line on USART1 (polled: works with interrupts off),
// then exit with kFaultExitCode. For faults that are not exceptions (an allocation after
// start-up).
// put_hex_for_fault: " name=0x%08X" written at p (no library call: a fault may come from it);
// returns the end.
char* put_hex_for_fault(char* p, const char* name, std::uint32_t v) noexcept;

[[noreturn]] void report_fatal(const char* text, std::uint32_t value) noexcept;

}  // namespace odo::board
