#include "odo/sim/sim_encoder.hpp"

#include "odo/odometry/count_delta.hpp"

namespace odo::sim {

std::int64_t SimEncoderSource::to_counter(std::int64_t counts) const noexcept {
  // The hardware register keeps only the low `bits_` bits; wrap_delta from 0 sign-extends them.
  return wrap_delta(0, counts + offset_, bits_);
}

EncoderSample SimEncoderSource::read(TimeNs now) noexcept {
  robot_.advance_to(now);
  EncoderSample s;
  s.left = to_counter(robot_.counts_left());
  s.right = to_counter(robot_.counts_right());
  s.stamp = now;
  if (delay_clock_ != nullptr && read_delay_ > 0) delay_clock_->advance(read_delay_);
  return s;
}

}  // namespace odo::sim
