#include "odo/calibration/fix_window.hpp"

#include <algorithm>
#include <iterator>

namespace odo::calib {

std::uint64_t FixWindow::take_ripe(TimeNs until) {
  std::stable_sort(pending_.begin(), pending_.end(),
                   [](const PoseFix& a, const PoseFix& b) { return a.t < b.t; });
  // Ripe: every count up to the fix time has been recorded (the open segment closes within
  // ripe_delay of the recorded time).
  std::uint64_t dropped = 0;
  std::size_t n = 0;
  for (; n < pending_.size() && pending_[n].t + p_.ripe_delay <= until; ++n) {
    const PoseFix& f = pending_[n];
    // Without a window, trim() keeps the counts of the last kKeep only: an older fix has lost
    // the counts after it. (A fix before the first segment is fine: the robot stood still.)
    const bool before_record = window_.empty() && f.t < until - kKeep;
    if ((!window_.empty() && f.t <= window_.back().t) || before_record) {
      ++dropped;
      continue;
    }
    window_.push_back(f);
    flagged_.push_back(false);
    ++new_fixes_;
  }
  pending_.erase(pending_.begin(), pending_.begin() + static_cast<std::ptrdiff_t>(n));
  return dropped;
}

void FixWindow::trim(TimeNs until) {
  if (window_.size() > p_.max_fixes) {
    const auto cut = static_cast<std::ptrdiff_t>(window_.size() - p_.max_fixes);
    window_.erase(window_.begin(), window_.begin() + cut);
    flagged_.erase(flagged_.begin(), flagged_.begin() + cut);
  }
  // Counts before the first fix of the window are of no use; without a fix, keep what a late
  // fix (at most 4.1 s on CAN) can still reach.
  const TimeNs keep_from = !window_.empty() ? window_.front().t : until - kKeep;
  while (!segs_.empty() && segs_.front().t_end <= keep_from) segs_.pop_front();
}

bool FixWindow::fit_due() {
  if (window_.size() < p_.min_fixes || new_fixes_ < p_.fit_every) return false;
  new_fixes_ = 0;
  return true;
}

std::uint64_t FixWindow::newly_rejected(const std::vector<int>& rejected) {
  std::uint64_t n = 0;
  for (const int i : rejected) {
    const auto k = static_cast<std::size_t>(i);
    if (k >= flagged_.size() || flagged_[k]) continue;
    flagged_[k] = true;
    ++n;
  }
  return n;
}

void FixWindow::restart_at_newest() {
  if (window_.empty()) return;
  window_.erase(window_.begin(), std::prev(window_.end()));
  flagged_.assign(1, false);
}

}  // namespace odo::calib
