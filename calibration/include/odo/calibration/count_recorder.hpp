// What the loop records for self-calibration from absolute fixes (issue 18): the wheel count
// increments of every tick, aggregated into short segments the estimator integrates as one
// constant-curvature arc each. Runs on the loop thread: fixed size, no allocation, no I/O.
//
// Aggregation and its error. The exact model integrates every tick as an arc (the loop's own
// odometry does the same). Summing the counts of several ticks into one segment replaces the
// heading profile phi(s) inside the segment by the straight line of an arc with the same end
// heading. Its position error is | int (e^{i phi(s)} - e^{i phi_lin(s)}) ds | <= S * max|phi -
// phi_lin| <= 2 S phi_H, where S is the segment's centre travel and phi_H = H c_m / b the largest
// heading change the segment may hold (H = max_turn_counts: the running count difference
// N_R - N_L of an open segment never leaves [-H, H]). A segment also closes when its travel
// reaches max_travel_counts, when a wheel reverses (a spin after a straight leg is two
// segments, not one blurred arc) and after max_duration, so that a fix time falling inside a
// segment can be matched by splitting it in proportion to time (exact at constant wheel speeds,
// off by at most a * dt^2 / 8 of travel under acceleration a). For constant-curvature motion
// the arc is exact and only the count quantisation remains.
// Defaults on the LabMate (c_m = 14.4 um/count, b = 0.34 m): H = 23 counts (1e-3 rad), 0.05 m,
// 20 ms: worst-case bound 1e-4 m per 0.05 m segment; measured in tests/unit/test_selfcal.cpp.
#pragma once

#include <cstdint>

#include "odo/hal/result.hpp"
#include "odo/hal/time.hpp"
#include "odo/odometry/kinematics.hpp"

namespace odo::calib {

// One recorded segment: the counts of the ticks in (t_start, t_end].
struct CountSegment {
  TimeNs t_start = 0;         // time of the tick before the segment's first tick [ns]
  TimeNs t_end = 0;           // time of the segment's last tick [ns]
  std::int32_t dn_left = 0;   // left wheel count increment [counts]
  std::int32_t dn_right = 0;  // right wheel count increment [counts]
};

// Closing thresholds in counts (derived once at configure time).
struct RecorderLimits {
  std::int32_t max_turn_counts = 0;    // H: |N_R - N_L| of an open segment stays <= H
  std::int32_t max_travel_counts = 0;  // |N_L| + |N_R| of a segment stays <= this
  TimeNs max_duration = 0;             // [ns]
};

// recorder_limits: thresholds for kinematics `k` from a heading change [rad], a centre travel
// [m] and a duration [s] per segment; each must be positive and finite, and give >= 1 count.
Result<RecorderLimits> recorder_limits(const Kinematics& k, double max_turn = 1e-3,
                                       double max_travel = 0.05, double max_duration = 0.02);

// CountRecorder: aggregates per-tick count increments into CountSegments.
class CountRecorder {
 public:
  explicit CountRecorder(const RecorderLimits& l) noexcept : l_(l) {}
  // start: the recording starts at time t [ns] (the tick whose counts are the reference).
  void start(TimeNs t) noexcept;
  // add_tick: adds the count increments of the tick at time t [ns]. Returns true and fills
  // `out` when adding it would break a limit: the open segment is closed first (it ends at the
  // previous tick) and this tick opens the next one. At most one segment per call.
  bool add_tick(TimeNs t, std::int64_t dn_left, std::int64_t dn_right, CountSegment& out) noexcept;
  // flush: closes the open segment (true when it holds counts), e.g. before a long pause.
  bool flush(CountSegment& out) noexcept;

 private:
  bool would_break(TimeNs t, std::int64_t dn_left, std::int64_t dn_right) const noexcept;

  RecorderLimits l_;
  CountSegment open_;
  TimeNs last_t_ = 0;
};

}  // namespace odo::calib
