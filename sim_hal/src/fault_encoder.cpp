#include "odo/sim/fault_encoder.hpp"

#include "odo/odometry/count_delta.hpp"

namespace odo::sim {
namespace {

// add_wrapping: a + b modulo 2^64, as the counter register adds (no signed overflow).
std::int64_t add_wrapping(std::int64_t a, std::int64_t b) noexcept {
  return static_cast<std::int64_t>(static_cast<std::uint64_t>(a) + static_cast<std::uint64_t>(b));
}

}  // namespace

EncoderSample FaultyEncoderSource::read(TimeNs now) noexcept {
  // The hardware keeps counting whatever happens to the read: the inner source always advances.
  EncoderSample s = inner_.read(now);
  const int bits = inner_.counter_bits();
  if (slow_left_ > 0) {
    --slow_left_;
    ++injected_.slow_reads;
    if (clock_ != nullptr) clock_->advance(delay_);
  }
  if (error_left_ > 0) {
    --error_left_;
    ++injected_.read_errors;
    ++read_errors_reported_;
    // What a failed bus transfer returns is undefined: hand out garbage the loop must ignore.
    s.left = wrap_delta(0, static_cast<std::int64_t>(0x5a5a5a5a5a5a5a5aULL), bits);
    s.right = wrap_delta(0, static_cast<std::int64_t>(0xa5a5a5a5a5a5a5a5ULL), bits);
    s.flags |= kEncoderReadError;
  } else {
    if (freeze_left_ > 0 && have_last_) {
      --freeze_left_;
      ++injected_.frozen_reads;
      if (freeze_l_) s.left = last_l_;
      if (freeze_r_) s.right = last_r_;
    }
    last_l_ = s.left;
    last_r_ = s.right;
    have_last_ = true;
    if (glitch_armed_) {
      glitch_armed_ = false;
      ++injected_.glitches;
      // Only this reading is wrong; last_* keep the true values for a later freeze.
      s.left = wrap_delta(0, add_wrapping(s.left, glitch_l_), bits);
      s.right = wrap_delta(0, add_wrapping(s.right, glitch_r_), bits);
    }
  }
  s.counters.read_errors += read_errors_reported_;
  return s;
}

}  // namespace odo::sim
