// FixWindow: the fixes and count segments one online self-calibration fit is made on, and when
// a fit is due (issue 18's policy; pure logic, moved out of the daemon's estimator thread by
// issue 33). The caller feeds it segments and fixes as they arrive and tells it how far the
// count record reaches; it keeps memory bounded for any run length.
#pragma once

#include <cstddef>
#include <cstdint>
#include <deque>
#include <vector>

#include "odo/calibration/count_recorder.hpp"
#include "odo/calibration/selfcal.hpp"
#include "odo/hal/time.hpp"

namespace odo::calib {

class FixWindow {
 public:
  // What is kept of the record while no fix is in the window: a late CAN fix is at most 4.1 s
  // old [ns].
  static constexpr TimeNs kKeep = 5'000'000'000;

  // The numbers are the daemon's [selfcal] keys (firmware/config.hpp owns their defaults and
  // ranges).
  struct Policy {
    std::size_t max_fixes = 0;  // the window's length in fixes (the oldest go first)
    std::size_t min_fixes = 0;  // fixes in the window before the first fit
    std::size_t fit_every = 0;  // new fixes between two fits
    TimeNs ripe_delay = 0;      // a fix is taken once the record reaches its time + this [ns]
  };

  explicit FixWindow(const Policy& p) : p_(p) {}

  // add_segment: a closed count segment of the record, in time order.
  void add_segment(const CountSegment& s) { segs_.push_back(s); }
  // add_fix: a fix as received (any order, possibly before its counts are recorded).
  void add_fix(const PoseFix& f) { pending_.push_back(f); }
  // take_ripe: the pending fixes whose counts the record holds by `until` [ns] enter the window
  // in time order; returns how many were dropped instead (not after the window's newest fix, or,
  // with an empty window, older than the kKeep of counts kept).
  std::uint64_t take_ripe(TimeNs until);
  // trim: at most max_fixes fixes; the segments before the window's first fix dropped (with no
  // fix: those ending more than kKeep before `until` [ns]).
  void trim(TimeNs until);
  // fit_due: whether a fit is due now (min_fixes in the window and fit_every new since the last
  // fit); the count of new fixes starts again when it is.
  bool fit_due();
  // newly_rejected: the window's fixes at `rejected` (indices of the last fit) not counted as
  // rejected before; marks them counted.
  std::uint64_t newly_rejected(const std::vector<int>& rejected);
  // restart_at_newest: after an accepted fit the next candidate must beat it on fixes it has
  // not seen: the window starts again at its newest fix.
  void restart_at_newest();

  const std::vector<PoseFix>& fixes() const noexcept { return window_; }
  // segments: a copy of the kept record, in time order (what build_track takes).
  std::vector<CountSegment> segments() const { return {segs_.begin(), segs_.end()}; }
  std::size_t segment_count() const noexcept { return segs_.size(); }
  std::size_t pending_count() const noexcept { return pending_.size(); }

 private:
  Policy p_;
  std::deque<CountSegment> segs_;
  std::vector<PoseFix> pending_;  // not ripe yet
  std::vector<PoseFix> window_;
  std::vector<bool> flagged_;  // window_[i] already counted as rejected
  std::size_t new_fixes_ = 0;
};

}  // namespace odo::calib
