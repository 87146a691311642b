// CountingEncoder: an encoder source that costs what a memory-mapped counter read costs: both
// counts advance by fixed steps per read (a constant arc). Separates the firmware's own cost
// of a tick from the simulated robot's.
#pragma once

#include "odo/hal/encoder.hpp"

namespace odo::bench {

class CountingEncoder final : public EncoderSource {
 public:
  // step_left/right: counts per read (e.g. 52/57: about 0.75 m/s on an arc at 1 kHz).
  CountingEncoder(std::int64_t step_left, std::int64_t step_right)
      : step_l_(step_left), step_r_(step_right) {}
  EncoderSample read(TimeNs now) noexcept override {
    left_ += step_l_;
    right_ += step_r_;
    EncoderSample s;
    s.left = left_;
    s.right = right_;
    s.stamp = now;
    return s;
  }
  int counter_bits() const noexcept override { return 32; }
  // set_steps: counts per read from the next read on (the driver sets them between ticks).
  void set_steps(std::int64_t step_left, std::int64_t step_right) noexcept {
    step_l_ = step_left;
    step_r_ = step_right;
  }

 private:
  std::int64_t step_l_, step_r_;
  std::int64_t left_ = 0, right_ = 0;
};

}  // namespace odo::bench
