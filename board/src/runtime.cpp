// What the C and C++ run-time libraries expect from a bare-metal system, and no more:
// 64-bit atomics (the loop's std::atomic<std::uint64_t> counters; a Cortex-M4 has no 64-bit
// exclusive access, and it has one core, so masking interrupts makes them atomic), abort
// (picolibc's raises a signal through kill/getpid, which a microcontroller has not), and memcpy
// (picolibc's, built for size, copies a byte at a time: 4 instructions a byte, 1.8k a tick for
// the loop's snapshot copies; a word at a time when both ends are aligned is 4x fewer), and
// double division (libgcc's bit-at-a-time __aeabi_ddiv is wrapped, -Wl,--wrap: soft_divide.hpp
// takes normal operands, libgcc's the rest), operator new and delete and the helpers that
// libstdc++'s headers call for a throw (std::__throw_*). The last two replace libstdc++'s own,
// which are built with exceptions: linking them (new_op.o, functexcept.o) linked the exception
// classes, the C++ personality routine and libgcc's ARM unwinder into a firmware built with
// -fno-exceptions, 6 KB that can never run. Here an allocation failure or a violated
// precondition is a fatal report, as abort() is.
#include <bit>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <new>

#include "odo/board/fault.hpp"
#include "odo/board/soft_divide.hpp"

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

// copy_bytes: memcpy's body. Not recognised as a memcpy (that would call itself).
[[gnu::optimize("no-tree-loop-distribute-patterns")]] static void copy_bytes(
    void* __restrict d, const void* __restrict s, std::size_t n) noexcept {
  using Word [[gnu::may_alias]] = std::uint32_t;
  auto* dc = static_cast<unsigned char*>(d);
  const auto* sc = static_cast<const unsigned char*>(s);
  if (((reinterpret_cast<std::uintptr_t>(dc) | reinterpret_cast<std::uintptr_t>(sc)) & 3U) == 0) {
    for (; n >= 4; n -= 4, dc += 4, sc += 4)
      *reinterpret_cast<Word*>(dc) = *reinterpret_cast<const Word*>(sc);
  }
  for (; n != 0; --n) *dc++ = *sc++;
}

// memcpy and its ARM EABI names (all of them here, so that picolibc's, which defines them
// together, is not linked as well).
void* memcpy(void* __restrict d, const void* __restrict s, std::size_t n) {
  copy_bytes(d, s, n);
  return d;
}
void __aeabi_memcpy(void* d, const void* s, std::size_t n) {
  copy_bytes(d, s, n);
}
void __aeabi_memcpy4(void* d, const void* s, std::size_t n) {
  copy_bytes(d, s, n);
}
void __aeabi_memcpy8(void* d, const void* s, std::size_t n) {
  copy_bytes(d, s, n);
}

// The run-time ABI's helpers take and return doubles in core registers, also under the
// hard-float ABI (pcs "aapcs").
[[gnu::pcs("aapcs")]] double __real___aeabi_ddiv(double a, double b);
[[gnu::pcs("aapcs")]] double __wrap___aeabi_ddiv(double a, double b) {
  std::uint64_t q = 0;
  if (odo::board::divide_normal(std::bit_cast<std::uint64_t>(a), std::bit_cast<std::uint64_t>(b),
                                q))
    return std::bit_cast<double>(q);
  return __real___aeabi_ddiv(a, b);
}

[[noreturn]] void abort() {
  odo::board::report_fatal("abort", 0);
}

}  // extern "C"

// Allocation: malloc (counted and refused after start-up, system.cpp) and, over-aligned,
// aligned_alloc with the size rounded up to the alignment as libstdc++'s operator new does; a
// failure is fatal (nothing could catch std::bad_alloc here).
void* operator new(std::size_t n) {
  void* p = std::malloc(n == 0 ? 1 : n);
  if (p == nullptr) odo::board::report_fatal("out of memory", n);
  return p;
}
void* operator new(std::size_t n, const std::nothrow_t&) noexcept {
  return std::malloc(n == 0 ? 1 : n);
}
void* operator new(std::size_t n, std::align_val_t a) {
  const auto al = static_cast<std::size_t>(a);
  void* p = ::aligned_alloc(al, (n + al - 1) & ~(al - 1));
  if (p == nullptr) odo::board::report_fatal("out of memory", n);
  return p;
}
void operator delete(void* p) noexcept {
  std::free(p);
}
void operator delete(void* p, std::size_t) noexcept {
  std::free(p);
}
void operator delete(void* p, std::align_val_t) noexcept {
  std::free(p);
}
void operator delete(void* p, std::size_t, std::align_val_t) noexcept {
  std::free(p);
}

// What libstdc++'s headers call where they would throw (bits/functexcept.h): a string or vector
// grown past max_size(), an index out of range (the core rooms do neither on purpose).
namespace std {
[[noreturn]] void __throw_bad_alloc() {
  odo::board::report_fatal("bad_alloc", 0);
}
[[noreturn]] void __throw_bad_array_new_length() {
  odo::board::report_fatal("bad_array_new_length", 0);
}
[[noreturn]] void __throw_length_error(const char*) {
  odo::board::report_fatal("length_error", 0);
}
[[noreturn]] void __throw_logic_error(const char*) {
  odo::board::report_fatal("logic_error", 0);
}
[[noreturn]] void __throw_out_of_range_fmt(const char*, ...) {
  odo::board::report_fatal("out_of_range", 0);
}
}  // namespace std
