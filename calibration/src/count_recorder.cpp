#include "odo/calibration/count_recorder.hpp"

#include <cmath>
#include <string>

#include "odo/hal/format.hpp"

namespace odo::calib {
namespace {

bool opposite(std::int64_t a, std::int64_t b) {
  return (a > 0 && b < 0) || (a < 0 && b > 0);
}

}  // namespace

Result<RecorderLimits> recorder_limits(const Kinematics& k, double max_turn, double max_travel,
                                       double max_duration) {
  const double c_m = k.metres_per_count();
  // A heading change phi needs (N_R - N_L) = phi b / c_m counts; a centre travel s needs
  // (|N_L| + |N_R|) = 2 s / c_m counts.
  const double turn = max_turn * k.wheelbase() / c_m;
  const double travel = 2.0 * max_travel / c_m;
  const struct {
    const char* field;
    double value;
    double counts;
  } checks[] = {{"max_turn", max_turn, turn},
                {"max_travel", max_travel, travel},
                {"max_duration", max_duration, max_duration * 1e9}};
  for (const auto& c : checks) {
    if (!(std::isfinite(c.value) && c.value > 0.0 && c.counts >= 1.0 && c.counts < 1e9)) {
      return make_error(Errc::kInvalidArgument,
                        std::string("recorder ") + c.field + " = " + general_text(c.value) +
                            " must be positive and give 1 .. 1e9 counts (or ns)");
    }
  }
  return RecorderLimits{static_cast<std::int32_t>(turn), static_cast<std::int32_t>(travel),
                        static_cast<TimeNs>(max_duration * 1e9)};
}

void CountRecorder::start(TimeNs t) noexcept {
  open_ = CountSegment{t, t, 0, 0};
  last_t_ = t;
}

bool CountRecorder::would_break(TimeNs t, std::int64_t dl, std::int64_t dr) const noexcept {
  if (open_.dn_left == 0 && open_.dn_right == 0) return false;  // an empty segment never breaks
  const std::int64_t l = open_.dn_left + dl;
  const std::int64_t r = open_.dn_right + dr;
  const std::int64_t turn = r - l;
  return turn > l_.max_turn_counts || -turn > l_.max_turn_counts ||
         std::llabs(l) + std::llabs(r) > l_.max_travel_counts || opposite(open_.dn_left, dl) ||
         opposite(open_.dn_right, dr) || t - open_.t_start > l_.max_duration;
}

bool CountRecorder::add_tick(TimeNs t, std::int64_t dl, std::int64_t dr,
                             CountSegment& out) noexcept {
  bool closed = false;
  if (would_break(t, dl, dr)) {
    out = open_;
    open_ = CountSegment{last_t_, last_t_, 0, 0};
    closed = true;
  } else if (open_.dn_left == 0 && open_.dn_right == 0 && dl == 0 && dr == 0) {
    // Standstill: no segment; the next one starts at this tick.
    open_.t_start = t;
  }
  // A single tick beyond the limits becomes a segment of its own (it cannot be split).
  open_.dn_left += static_cast<std::int32_t>(dl);
  open_.dn_right += static_cast<std::int32_t>(dr);
  open_.t_end = t;
  last_t_ = t;
  return closed;
}

bool CountRecorder::flush(CountSegment& out) noexcept {
  const bool any = open_.dn_left != 0 || open_.dn_right != 0;
  if (any) out = open_;
  open_ = CountSegment{last_t_, last_t_, 0, 0};
  return any;
}

}  // namespace odo::calib
