// TimerClock: the loop's Clock on the Cortex-M4's SysTick timer. Its interrupt comes once a
// loop period (reload = one period of core clocks); now() = periods elapsed * period + the
// counter's progress. The clock stands at 0 until the loop first sleeps (the loop's start()
// latches the reference reading at time 0, as odometryd's virtual clock does); sleep_until waits
// for interrupts (WFI), so the loop's absolute deadlines are the reloads and its missed-deadline
// accounting sees real overruns.
//
// Why SysTick and not TIM2: QEMU 7.2's STM32 timer model never reloads its counter at ARR (TIM2
// CNT read 39220138 after 40 ms with ARR = 9999999 at 1 GHz, and the update interrupts came at
// wrong times: 107 missed deadlines in 200 ticks), so a TIM2 time base cannot be tested in
// QEMU; SysTick is the core's, the same on the chip and in QEMU's model.
//
// At each reload the interrupt also latches the encoders (LatchedEncoder): the sample's time is
// the reload's exact time, so a tick's counts belong to its deadline, not to when the loop got
// round to reading them.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>

#include "odo/hal/clock.hpp"
#include "odo/hal/encoder.hpp"
#include "odo/hal/side_wheels.hpp"

namespace odo::board {

class TimerClock final : public Clock {
 public:
  // configure: period [ns] of the interrupt, the core clock tim_hz [Hz] that SysTick counts.
  void configure(TimeNs period, std::uint32_t tim_hz) noexcept;
  TimeNs now() noexcept override;
  void sleep_until(TimeNs deadline) noexcept override;
  // on_update: the SysTick interrupt's body.
  void on_update() noexcept;
  // set_latch: the encoder read at every update (configure time).
  void set_latch(class LatchedEncoder* e) noexcept { latch_ = e; }
  TimeNs period() const noexcept { return period_; }

 private:
  void start_timer() noexcept;
  TimeNs period_ = 0;
  std::uint32_t tim_hz_ = 1;
  std::uint32_t counts_ = 1;  // timer counts a period
  std::atomic<std::uint32_t> periods_{0};
  bool running_ = false;
  LatchedEncoder* latch_ = nullptr;
};

// LatchedEncoder: an EncoderSource whose read() returns the sample the timer interrupt took at
// the last update (the inner source read at that update's time). With several wheels per side,
// the inner source's per-wheel readings are latched with its sample, so that wheels() belongs to
// the sample read() returned even when a late tick reads after the next update.
class LatchedEncoder final : public EncoderSource {
 public:
  // `wheels`: the inner source's per-wheel readings of its last read ([0] left, [1] right), or
  // null with one wheel per side.
  explicit LatchedEncoder(EncoderSource& inner,
                          const std::array<SideReadings, 2>* wheels = nullptr) noexcept
      : inner_(&inner), wheels_in_(wheels) {}
  // latch: reads the inner source at `t` [ns] (interrupt context, or before the timer runs).
  void latch(TimeNs t) noexcept;
  EncoderSample read(TimeNs now) noexcept override;
  int counter_bits() const noexcept override { return inner_->counter_bits(); }
  // wheels: the per-wheel readings of the sample the last read() returned (all zero without).
  const std::array<SideReadings, 2>& wheels() const noexcept { return wheels_read_; }

 private:
  EncoderSource* inner_;
  const std::array<SideReadings, 2>* wheels_in_;
  EncoderSample sample_{};
  std::array<SideReadings, 2> wheels_latched_{};
  std::array<SideReadings, 2> wheels_read_{};
};

TimerClock& timer_clock() noexcept;

}  // namespace odo::board
