#include "odo/board/timer_clock.hpp"

#include "odo/board/stm32f4.hpp"

namespace odo::board {

namespace {
// SysTick (Cortex-M4 core): control/status, reload, current value; ICSR's pending bit.
constexpr std::uintptr_t kSystCsr = 0xE000E010, kSystRvr = 0xE000E014, kSystCvr = 0xE000E018;
constexpr std::uintptr_t kIcsr = 0xE000ED04;
constexpr std::uint32_t kPendStSet = 1u << 26;
}  // namespace

void TimerClock::configure(TimeNs period, std::uint32_t tim_hz) noexcept {
  period_ = period;
  tim_hz_ = tim_hz;
  counts_ = static_cast<std::uint32_t>(period * static_cast<TimeNs>(tim_hz) / kNsPerSecond);
  reg(kSystCsr) = 0;
  reg(kSystRvr) = counts_ - 1;  // 24 bits: >= 10 Hz at 168 MHz
  reg(kSystCvr) = 0;
}

void TimerClock::start_timer() noexcept {
  running_ = true;
  // Priority 1 (above the UARTs): the deadline is the loop's time base.
  *reinterpret_cast<volatile std::uint8_t*>(0xE000ED23) = 1u << 4;  // SHPR3: SysTick
  reg(kSystCvr) = 0;
  reg(kSystCsr) = 0x7;  // processor clock, interrupt, enable
}

TimeNs TimerClock::now() noexcept {
  if (!running_) return 0;
  for (;;) {
    // A reload whose interrupt has not run yet (pending) already started the next period: it
    // counts when it was pending before and after the counter was read.
    const std::uint32_t p1 = periods_.load(std::memory_order_acquire);
    const std::uint32_t pend1 = (reg(kIcsr) & kPendStSet) != 0 ? 1u : 0u;
    const std::uint32_t val = reg(kSystCvr);
    const std::uint32_t pend2 = (reg(kIcsr) & kPendStSet) != 0 ? 1u : 0u;
    if (p1 != periods_.load(std::memory_order_acquire) || pend1 != pend2) continue;
    // The counter counts down from counts_ - 1 (0 right after enabling: a period has begun).
    const std::uint32_t elapsed = val == 0 ? 0 : counts_ - 1 - val;
    const TimeNs sub = static_cast<TimeNs>(elapsed) * kNsPerSecond / static_cast<TimeNs>(tim_hz_);
    return static_cast<TimeNs>(p1 + pend1) * period_ + sub;
  }
}

void TimerClock::sleep_until(TimeNs deadline) noexcept {
  if (!running_) start_timer();
  for (;;) {
    // Interrupts masked between the check and WFI: a reload in between stays pending and
    // ends the WFI at once instead of being slept through.
    asm volatile("cpsid i" ::: "memory");
    if (now() >= deadline) break;
    asm volatile("wfi");
    asm volatile("cpsie i" ::: "memory");
  }
  asm volatile("cpsie i" ::: "memory");
}

void TimerClock::on_update() noexcept {
  const std::uint32_t p = periods_.load(std::memory_order_relaxed) + 1;
  if (latch_ != nullptr) latch_->latch(static_cast<TimeNs>(p) * period_);
  periods_.store(p, std::memory_order_release);
}

void LatchedEncoder::latch(TimeNs t) noexcept {
  sample_ = inner_->read(t);
  if (wheels_in_ != nullptr) wheels_latched_ = *wheels_in_;
}

EncoderSample LatchedEncoder::read(TimeNs) noexcept {
  asm volatile("cpsid i" ::: "memory");
  const EncoderSample s = sample_;
  if (wheels_in_ != nullptr) wheels_read_ = wheels_latched_;
  asm volatile("cpsie i" ::: "memory");
  return s;
}

TimerClock& timer_clock() noexcept {
  static constinit TimerClock c;
  return c;
}

}  // namespace odo::board

extern "C" void odo_systick_irq() {
  odo::board::timer_clock().on_update();
}
