// Vector table, reset and fault handlers. The start-up proper (.data, .bss, TLS, constructors,
// main, exit) is picolibc's crt0 (_start); the linker script is picolibc's picolibc.ld with this
// chip's memory sizes (board/CMakeLists.txt). crt0 expects the vector table as the symbol
// __interrupt_vector in section .text.init.enter, which picolibc.ld places first in flash.
#include <array>
#include <cstdint>

#include "odo/board/fault.hpp"
#include "odo/board/stm32f4.hpp"

extern "C" {
[[noreturn]] void _start();
extern std::uint32_t __stack[];
void odo_systick_irq();
void odo_usart1_irq();
void odo_usart2_irq();
[[noreturn]] void odo_fault_handler_c(const std::uint32_t* frame, std::uint32_t exc);

// odo_reset: the FPU on (CP10, CP11 full access) before any code may use it, then crt0.
[[noreturn]] void odo_reset() {
  odo::board::reg(odo::board::scb::kCpacr) |= 0xFu << 20;
  asm volatile("dsb\n isb" ::: "memory");
  _start();
}

// odo_fault: every fault and unexpected interrupt. The stacked frame (MSP or PSP by EXC_RETURN
// bit 2) and the exception number go to the C++ reporter.
[[gnu::naked]] void odo_fault() {
  asm volatile(
      "tst lr, #4\n"
      "ite eq\n"
      "mrseq r0, msp\n"
      "mrsne r0, psp\n"
      "mrs r1, ipsr\n"
      "b odo_fault_handler_c\n");
}
}

namespace {

using Handler = void (*)();
constexpr int kVectors = 16 + odo::board::kIrqCount;

// handlers: entries 1.. of the table: reset, then every core exception and interrupt to the fault
// reporter except the reserved ones and the interrupts the board uses.
constexpr std::array<Handler, kVectors - 1> handlers() {
  std::array<Handler, kVectors - 1> v{};
  for (auto& h : v) h = odo_fault;
  v[0] = odo_reset;
  for (int i : {7, 8, 9, 10, 13}) v[i - 1] = nullptr;  // reserved
  v[15 - 1] = odo_systick_irq;
  v[16 + odo::board::kIrqUsart1 - 1] = odo_usart1_irq;
  v[16 + odo::board::kIrqUsart2 - 1] = odo_usart2_irq;
  return v;
}

struct VectorTable {
  std::uint32_t* stack;  // initial main stack pointer (picolibc.ld: top of RAM)
  std::array<Handler, kVectors - 1> handlers;
};

}  // namespace

extern "C" [[gnu::used,
             gnu::section(".text.init.enter")]] constinit const VectorTable __interrupt_vector = {
    __stack, handlers()};
