// QuadTracker: turns time-ordered edge events of one wheel's A and B lines into counts with the
// 4x table (odo/hal/quadrature.hpp). Pure: no I/O, no clock; the libgpiod thread feeds it.
// An event that does not change the line it names means an edge was lost (the kernel's event
// queue overflowed); events of both lines with the same timestamp mean both changed at once.
// Either is counted as an invalid transition and never turned into motion: the tracker takes
// the new levels as the truth and goes on from there.
#pragma once

#include <cstdint>

#include "odo/hal/quadrature.hpp"

namespace odo::drivers {

class QuadTracker {
 public:
  static constexpr std::uint8_t kLineA = 2;  // bit of A in QuadState
  static constexpr std::uint8_t kLineB = 1;  // bit of B

  // reset: start from the sampled levels, keeping the count.
  void reset(QuadState s) noexcept { state_ = s; }

  // apply: the lines in `mask` (kLineA | kLineB) changed, at the same instant, to the levels in
  // `levels` (same bit layout). Returns the step taken.
  QuadStep apply(std::uint8_t mask, std::uint8_t levels) noexcept {
    mask &= 3u;
    const auto next = static_cast<QuadState>((state_ & ~mask) | (levels & mask));
    QuadStep step = quad_decode(state_, next);
    // A single-line event that changes nothing: the opposite edge before it was lost.
    if (step == QuadStep::kNone && mask != 0) step = QuadStep::kInvalid;
    if (step == QuadStep::kInvalid) ++invalid_;
    count_ += quad_delta(step);
    state_ = next;
    return step;
  }

  // resync: the levels read from the hardware; a difference from the tracked state means edges
  // were lost: counted as invalid, adopted without motion. Returns true when they differed.
  bool resync(QuadState actual) noexcept {
    if ((actual & 3u) == state_) return false;
    ++invalid_;
    state_ = actual & 3u;
    return true;
  }

  // adopt: an edge that arrived out of time order (older than one already applied): its
  // direction cannot be known any more; counted as invalid, its level taken without motion.
  void adopt(std::uint8_t mask, std::uint8_t levels) noexcept {
    mask &= 3u;
    ++invalid_;
    state_ = static_cast<QuadState>((state_ & ~mask) | (levels & mask));
  }

  std::int64_t count() const noexcept { return count_; }
  std::uint64_t invalid() const noexcept { return invalid_; }
  QuadState state() const noexcept { return state_; }

 private:
  QuadState state_ = 0;
  std::int64_t count_ = 0;
  std::uint64_t invalid_ = 0;
};

}  // namespace odo::drivers
