#include "odo/loop/recording_encoder.hpp"

#include "odo/odometry/count_delta.hpp"

namespace odo::loop {

EncoderSample RecordingEncoder::read(TimeNs now) noexcept {
  const EncoderSample s = inner_->read(now);
  // A failed read carries no counts; the loop skips it too, and the next good reading's
  // increments cover the gap (counts are cumulative).
  if ((s.flags & kEncoderReadError) != 0) return s;
  if (!started_) {
    rec_.start(s.stamp);
    started_ = true;
  } else {
    const int bits = inner_->counter_bits();
    calib::CountSegment seg;
    if (rec_.add_tick(s.stamp, wrap_delta(prev_left_, s.left, bits),
                      wrap_delta(prev_right_, s.right, bits), seg))
      ring_->push(seg);
  }
  prev_left_ = s.left;
  prev_right_ = s.right;
  until_.store(s.stamp, std::memory_order_release);
  return s;
}

}  // namespace odo::loop
