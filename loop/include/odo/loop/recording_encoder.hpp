// RecordingEncoder: what the loop records for self-calibration (issue 18). An EncoderSource
// decorator the loop reads through: every reading is passed on unchanged, and its wrap-aware
// count increments go into a calib::CountRecorder whose closed segments are pushed into an
// SpscRing for the estimator thread. The hook costs the loop no change and the recording runs
// on the loop thread inside its encoder read: fixed size, no allocation, no lock, no I/O.
#pragma once

#include <atomic>

#include "odo/calibration/count_recorder.hpp"
#include "odo/calibration/selfcal.hpp"
#include "odo/hal/encoder.hpp"
#include "odo/loop/spsc_ring.hpp"

namespace odo::loop {

using SegmentRing = SpscRing<calib::CountSegment>;
// FixRing: absolute fixes received on the loop thread (CAN), on their way to the estimator.
using FixRing = SpscRing<calib::PoseFix>;

class RecordingEncoder final : public EncoderSource {
 public:
  // inner: the real source (not owned); ring: where closed segments go (not owned).
  RecordingEncoder(EncoderSource& inner, const calib::RecorderLimits& limits,
                   SegmentRing& ring) noexcept
      : inner_(&inner), rec_(limits), ring_(&ring) {}

  EncoderSample read(TimeNs now) noexcept override;
  int counter_bits() const noexcept override { return inner_->counter_bits(); }

  // recorded_until: sample time [ns] up to which every count is in the ring or in the open
  // segment, which closes within RecorderLimits::max_duration plus one tick; any thread.
  TimeNs recorded_until() const noexcept { return until_.load(std::memory_order_acquire); }
  // flush: closes the open segment into the ring (the thread that reads; offline at the end of
  // a log, never while a loop runs on it).
  void flush() noexcept {
    calib::CountSegment seg;
    if (rec_.flush(seg)) ring_->push(seg);
  }

 private:
  EncoderSource* inner_;
  calib::CountRecorder rec_;
  SegmentRing* ring_;
  bool started_ = false;
  std::int64_t prev_left_ = 0;
  std::int64_t prev_right_ = 0;
  std::atomic<TimeNs> until_{0};
};

}  // namespace odo::loop
