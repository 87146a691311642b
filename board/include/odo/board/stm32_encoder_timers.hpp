// Stm32EncoderTimers: the wheels' quadrature signals counted by TIM3 (left) and TIM4 (right) in
// encoder mode 3 (every edge of both channels: x4), 16-bit counters read as they are; the loop's
// wrap-aware delta (odometry/count_delta) takes them across the wrap, so between two readings a
// wheel may move at most 32767 counts (at 100 Hz and 65536 counts a wheel turn: 50 turns/s).
// Register access through a RegisterBus: MmioBus on the chip, sim::Stm32TimerModel on the host.
#pragma once

#include <cstdint>

#include "odo/hal/encoder.hpp"
#include "odo/hal/register_bus.hpp"

namespace odo::board {

class Stm32EncoderTimers final : public EncoderSource {
 public:
  static constexpr std::uint32_t kTim3 = 0x40000400, kTim4 = 0x40000800;

  explicit Stm32EncoderTimers(RegisterBus& bus) noexcept : bus_(&bus) {}
  // init: both timers stopped, inputs TI1/TI2 non-inverted with a 4-sample filter, encoder mode
  // 3, the full 16-bit range, counters cleared and started (the timers' clocks are the RCC's).
  void init() noexcept;
  // read: both counters as they are [counts] (0..65535), stamped `now` [ns].
  EncoderSample read(TimeNs now) noexcept override;
  int counter_bits() const noexcept override { return 16; }

 private:
  void init_timer(std::uint32_t base) noexcept;
  RegisterBus* bus_;
};

}  // namespace odo::board
