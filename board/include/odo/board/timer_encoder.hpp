// TimerEncoder: the two wheels' quadrature signals counted by TIM3 (left) and TIM4 (right) in
// encoder mode 3 (both edges of both channels: 4x), 16-bit counters read as they are; the loop's
// wrap-aware delta (odometry/count_delta) handles the wrap. The real board's encoder source.
#pragma once

#include "odo/hal/encoder.hpp"

namespace odo::board {

class TimerEncoder final : public EncoderSource {
 public:
  // init: RCC clocks, encoder mode, full 16-bit range, counters started.
  void init() noexcept;
  EncoderSample read(TimeNs now) noexcept override;
  int counter_bits() const noexcept override { return 16; }
};

}  // namespace odo::board
