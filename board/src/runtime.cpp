// What the C and C++ run-time libraries expect from a bare-metal system, and no more:
// 64-bit atomics (the loop's std::atomic<std::uint64_t> counters; a Cortex-M4 has no 64-bit
// exclusive access, and it has one core, so masking interrupts makes them atomic), and abort
// (picolibc's raises a signal through kill/getpid, which a microcontroller has not).
#include <cstdint>

#include "odo/board/fault.hpp"

namespace {

// Irq: masks interrupts for its scope, restoring PRIMASK as it was (nesting-safe).
class Irq {
 public:
  Irq() noexcept { asm volatile("mrs %0, primask\n cpsid i" : "=r"(primask_)::"memory"); }
  ~Irq() { asm volatile("msr primask, %0" ::"r"(primask_) : "memory"); }
  Irq(const Irq&) = delete;
  Irq& operator=(const Irq&) = delete;

 private:
  std::uint32_t primask_;
};

}  // namespace

extern "C" {

std::uint64_t __atomic_load_8(const volatile void* p, int) {
  const Irq irq;
  return *static_cast<const volatile std::uint64_t*>(p);
}

void __atomic_store_8(volatile void* p, std::uint64_t v, int) {
  const Irq irq;
  *static_cast<volatile std::uint64_t*>(p) = v;
}

std::uint64_t __atomic_fetch_add_8(volatile void* p, std::uint64_t v, int) {
  const Irq irq;
  auto* q = static_cast<volatile std::uint64_t*>(p);
  const std::uint64_t old = *q;
  *q = old + v;
  return old;
}

std::uint64_t __atomic_exchange_8(volatile void* p, std::uint64_t v, int) {
  const Irq irq;
  auto* q = static_cast<volatile std::uint64_t*>(p);
  const std::uint64_t old = *q;
  *q = v;
  return old;
}

bool __atomic_compare_exchange_8(volatile void* p, void* expected, std::uint64_t desired, bool, int,
                                 int) {
  const Irq irq;
  auto* q = static_cast<volatile std::uint64_t*>(p);
  auto* e = static_cast<std::uint64_t*>(expected);
  if (*q == *e) {
    *q = desired;
    return true;
  }
  *e = *q;
  return false;
}

[[noreturn]] void abort() {
  odo::board::report_fatal("abort", 0);
}

}  // extern "C"
