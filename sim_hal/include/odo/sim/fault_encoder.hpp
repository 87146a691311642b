// FaultyEncoderSource: wraps any EncoderSource and injects the faults of a real encoder interface
// on demand, so tests and the soak can check what the loop does with them:
//   slow reads     every read costs extra virtual time (a slow bus): deadline overruns;
//   read errors    the backend cannot read the hardware: kEncoderReadError, garbage counts;
//   frozen counter the reading stops changing (wire cut, dead chip); no flag: detecting that is
//                  the backend's job (stale timeout), so the wrapper reports it as the hardware
//                  would, silently;
//   glitch         one reading off by a number of counts, the next one right again (EMI on the
//                  bus); no flag, for the same reason.
// More kinds (invalid quadrature bursts, stuck-at jumps) slot in as further arm_*() calls.
// Faults are armed for a number of reads; the wrapper counts what it injected.
#pragma once

#include <cstdint>

#include "odo/hal/encoder.hpp"
#include "odo/sim/virtual_clock.hpp"

namespace odo::sim {

// What a FaultyEncoderSource injected so far (reads affected, per kind).
struct InjectedFaults {
  std::uint64_t slow_reads = 0;
  std::uint64_t read_errors = 0;
  std::uint64_t frozen_reads = 0;
  std::uint64_t glitches = 0;
};

class FaultyEncoderSource final : public EncoderSource {
 public:
  // inner: the real (simulated) source, not owned; clock: advanced by slow reads (may be null
  // when no slow reads are armed).
  FaultyEncoderSource(EncoderSource& inner, VirtualClock* clock) : inner_(inner), clock_(clock) {}

  EncoderSample read(TimeNs now) noexcept override;
  int counter_bits() const noexcept override { return inner_.counter_bits(); }

  // arm_slow_reads: the next `reads` reads each take `delay` [ns] of virtual time.
  void arm_slow_reads(int reads, TimeNs delay) noexcept {
    slow_left_ = reads;
    delay_ = delay;
  }
  // arm_read_errors: the next `reads` reads fail (kEncoderReadError, counts are garbage).
  void arm_read_errors(int reads) noexcept { error_left_ = reads; }
  // arm_freeze: for the next `reads` reads the chosen counters repeat their last good value.
  void arm_freeze(int reads, bool left, bool right) noexcept {
    freeze_left_ = reads;
    freeze_l_ = left;
    freeze_r_ = right;
  }
  // arm_glitch: the next read is off by (dl, dr) counts; the one after is right again.
  void arm_glitch(std::int64_t dl, std::int64_t dr) noexcept {
    glitch_armed_ = true;
    glitch_l_ = dl;
    glitch_r_ = dr;
  }
  // idle: no fault is armed.
  bool idle() const noexcept {
    return slow_left_ == 0 && error_left_ == 0 && freeze_left_ == 0 && !glitch_armed_;
  }
  const InjectedFaults& injected() const noexcept { return injected_; }

 private:
  EncoderSource& inner_;
  VirtualClock* clock_;
  int slow_left_ = 0;
  TimeNs delay_ = 0;
  int error_left_ = 0;
  int freeze_left_ = 0;
  bool freeze_l_ = false, freeze_r_ = false;
  bool glitch_armed_ = false;
  std::int64_t glitch_l_ = 0, glitch_r_ = 0;
  std::int64_t last_l_ = 0, last_r_ = 0;  // last reading handed out (for a frozen counter)
  bool have_last_ = false;
  std::uint64_t read_errors_reported_ = 0;
  InjectedFaults injected_;
};

}  // namespace odo::sim
