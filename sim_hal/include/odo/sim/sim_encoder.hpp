// SimEncoderSource: the simulated robot's encoders as an EncoderSource, with a counter of any
// width from 16 to 64 bits so that wrap-around is exercised exactly as on hardware.
#pragma once

#include "odo/hal/encoder.hpp"
#include "odo/sim/robot.hpp"
#include "odo/sim/virtual_clock.hpp"

namespace odo::sim {

class SimEncoderSource final : public EncoderSource {
 public:
  // robot: the simulated base (not owned); bits: counter width; offset: counter value at zero
  // counts, to start a test close to the wrap.
  SimEncoderSource(SimRobot& robot, int bits = 32, std::int64_t offset = 0)
      : robot_(robot), bits_(bits), offset_(offset) {}

  // read: advances the robot to `now` and latches both counters.
  EncoderSample read(TimeNs now) noexcept override;
  int counter_bits() const noexcept override { return bits_; }

  // set_read_delay: every read costs `delay` [ns] of virtual time on `clock` (a slow bus), so a
  // test can force the loop to overrun its deadlines. delay 0 switches it off.
  void set_read_delay(VirtualClock* clock, TimeNs delay) noexcept {
    delay_clock_ = clock;
    read_delay_ = delay;
  }

 private:
  std::int64_t to_counter(std::int64_t counts) const noexcept;
  SimRobot& robot_;
  int bits_;
  std::int64_t offset_;
  VirtualClock* delay_clock_ = nullptr;
  TimeNs read_delay_ = 0;
};

}  // namespace odo::sim
