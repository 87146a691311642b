#include "odo/board/fault.hpp"

#include "odo/board/stm32f4.hpp"
#include "odo/board/system.hpp"
#include "odo/board/uart.hpp"

namespace odo::board {

// put_hex_for_fault: " name=0x%08X" into p; returns the end.
char* put_hex_for_fault(char* p, const char* name, std::uint32_t v) noexcept {
  *p++ = ' ';
  while (*name != '\0') *p++ = *name++;
  *p++ = '=';
  *p++ = '0';
  *p++ = 'x';
  for (int i = 7; i >= 0; --i) *p++ = "0123456789ABCDEF"[(v >> (4 * i)) & 0xFu];
  return p;
}

void report_fatal(const char* text, std::uint32_t value) noexcept {
  asm volatile("cpsid i" ::: "memory");
  char line[96];
  char* p = line;
  for (const char* t = "\r# FATAL "; *t != '\0';) *p++ = *t++;
  for (int i = 0; text[i] != '\0' && i < 48; ++i) *p++ = text[i];
  p = put_hex_for_fault(p, "value", value);
  *p++ = '\r';
  *p = '\0';
  uart1().write_polled(line);
  semihost_exit(kFaultExitCode);
}

}  // namespace odo::board

// odo_fault_handler_c: the naked odo_fault's C++ half: frame = the stacked r0-r3, r12, lr, pc,
// xpsr; exc = IPSR (3 HardFault, 4 MemManage, 5 BusFault, 6 UsageFault, 16+ an interrupt).
extern "C" [[noreturn]] void odo_fault_handler_c(const std::uint32_t* frame, std::uint32_t exc) {
  using odo::board::reg;
  namespace scb = odo::board::scb;
  static constexpr const char* kNames[] = {"r0", "r1", "r2", "r3", "r12", "lr", "pc", "xpsr"};
  char line[256];
  char* p = line;
  for (const char* t = "\r# FAULT"; *t != '\0';) *p++ = *t++;
  p = odo::board::put_hex_for_fault(p, "exc", exc);
  for (int i = 0; i < 8; ++i) p = odo::board::put_hex_for_fault(p, kNames[i], frame[i]);
  p = odo::board::put_hex_for_fault(p, "cfsr", reg(scb::kCfsr));
  p = odo::board::put_hex_for_fault(p, "hfsr", reg(scb::kHfsr));
  p = odo::board::put_hex_for_fault(p, "mmfar", reg(scb::kMmfar));
  p = odo::board::put_hex_for_fault(p, "bfar", reg(scb::kBfar));
  *p++ = '\r';
  *p = '\0';
  odo::board::uart1().write_polled(line);
  odo::board::semihost_exit(odo::board::kFaultExitCode);
}
