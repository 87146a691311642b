// Stm32EncoderTimers: the wheels' quadrature signals counted by TIM3 (left) and TIM4 (right) in
// encoder mode 3 (every edge of both channels: x4), 16-bit counters read as they are; the loop's
// wrap-aware delta (odometry/count_delta) takes them across the wrap, so between two readings a
// wheel may move at most 32767 counts (at 100 Hz and 65536 counts a wheel turn: 50 turns/s).
// Register access through a RegisterBus: MmioBus on the chip, sim::Stm32TimerModel on the host.
#pragma once

#include <array>
#include <cstdint>
#include <optional>

#include "odo/hal/encoder.hpp"
#include "odo/hal/register_bus.hpp"
#include "odo/hal/side_wheels.hpp"

namespace odo::board {

// The F405's timers with an encoder mode that the board leaves free (TIM2 is too, SysTick being
// the loop's clock; TIM9-14 have none): RM0090 18.3.12 and 17.3.16.
inline constexpr std::uint32_t kTim3 = 0x40000400, kTim4 = 0x40000800;
inline constexpr std::uint32_t kTim5 = 0x40000C00, kTim8 = 0x40010400;

// init_encoder_timer: the timer at `base` stopped, inputs TI1/TI2 non-inverted with an 8-sample
// filter, encoder mode 3, the 16-bit range, counter cleared and started.
void init_encoder_timer(RegisterBus& bus, std::uint32_t base) noexcept;
// read_encoder_timer: the counter of the timer at `base` (0..65535) [counts].
std::int64_t read_encoder_timer(RegisterBus& bus, std::uint32_t base) noexcept;

class Stm32EncoderTimers final : public EncoderSource {
 public:
  static constexpr std::uint32_t kTim3 = board::kTim3, kTim4 = board::kTim4;

  explicit Stm32EncoderTimers(RegisterBus& bus) noexcept : bus_(&bus) {}
  // init: both timers stopped, inputs TI1/TI2 non-inverted with a 4-sample filter, encoder mode
  // 3, the full 16-bit range, counters cleared and started (the timers' clocks are the RCC's).
  void init() noexcept;
  // read: both counters as they are [counts] (0..65535), stamped `now` [ns].
  EncoderSample read(TimeNs now) noexcept override;
  int counter_bits() const noexcept override { return 16; }

 private:
  RegisterBus* bus_;
};

// Stm32SideTimers: two wheels per side (a 4WD base, issue 38): TIM3 and TIM5 count the left
// wheels, TIM4 and TIM8 the right ones, each as Stm32EncoderTimers' timers; SideCombiner forms
// each side's count from its wheels (wrap-aware per wheel, 16 bits), so the combined counts never
// wrap. readings() keeps every wheel's counter of the last read (the serial counts version 2
// records carry them).
class Stm32SideTimers final : public EncoderSource {
 public:
  static constexpr std::array<std::uint32_t, 2> kLeft{kTim3, kTim5}, kRight{kTim4, kTim8};

  // create: the combination `c` for two wheels per side of 16-bit counters; nullopt when it is
  // outside check_side_wheels' ranges (SideCombiner::make: the board's configuration is built
  // in, so no message text is carried for it).
  static std::optional<Stm32SideTimers> create(RegisterBus& bus, SideWheelsConfig c) noexcept;
  // init: all four timers configured and started (their clocks are the RCC's).
  void init() noexcept;
  // read: the four counters latched at `now` [ns] and combined per side.
  EncoderSample read(TimeNs now) noexcept override;
  int counter_bits() const noexcept override { return 64; }
  // readings: every wheel's counter of the last read, [0] left, [1] right.
  const std::array<SideReadings, 2>& readings() const noexcept { return readings_; }
  const SideCombiner& combiner() const noexcept { return combiner_; }

 private:
  Stm32SideTimers(RegisterBus& bus, SideCombiner c) noexcept : bus_(&bus), combiner_(c) {}
  RegisterBus* bus_;
  SideCombiner combiner_;
  std::array<SideReadings, 2> readings_{};
};

}  // namespace odo::board
