#include "status_line.hpp"

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdio>
#include <iomanip>
#include <ostream>
#include <string>

#include "odo/firmware/timing_report.hpp"
#include "odo/hal/angle.hpp"
#include "odo/hal/encoder.hpp"
#include "odo/hal/gyro.hpp"

namespace odo::fw {
namespace {

// bits_text: the names of the bits set in f, joined by '|'; "" when none is.
template <class Table>
std::string bits_text(std::uint32_t f, const Table& names) {
  std::string s;
  for (const auto& b : names) {
    if (f & b.value) s += (s.empty() ? "" : "|") + std::string(b.name);
  }
  return s;
}

std::string flags_text(std::uint32_t f) {
  return f == 0 ? "ok" : bits_text(f, kEncoderFlagNames);
}

struct Count {
  const char* name;
  std::uint64_t value;
};

// counts_text: " (name=value ...)" of N event counters, "" while all are 0.
template <std::size_t N>
std::string counts_text(const std::array<Count, N>& counts) {
  if (std::all_of(counts.begin(), counts.end(), [](const Count& c) { return c.value == 0; }))
    return {};
  std::string s = " (";
  for (std::size_t i = 0; i < counts.size(); ++i)
    s += (i > 0 ? " " : "") + std::string(counts[i].name) + "=" + std::to_string(counts[i].value);
  return s + ")";
}

// gyro_text: the status line's gyro part: what the fusion does this tick (the sample's flags
// when it has any, "non-finite" for a NaN/inf rate without one, else learning-bias or fusing),
// and the event counters once there is something to count.
std::string gyro_text(const loop::LoopGyroStatus& g) {
  std::string s = "  gyro=";
  if (g.gyro_flags != 0)
    s += bits_text(g.gyro_flags, kGyroFlagNames);
  else if ((g.fusion_flags & kFusionGyroFault) != 0)
    s += "non-finite";
  else
    s += g.bias_valid ? "fusing" : "learning-bias";
  const FusionCounters& c = g.fusion;
  return s + counts_text<4>({{{"disagreements", c.disagreements},
                              {"speed", c.speed_events},
                              {"accel", c.accel_events},
                              {"faults", c.gyro_faults}}});
}

// counters_text: the cumulative encoder fault counters, once there is something to count (a
// fault between two status lines would otherwise be invisible in the per-sample flags).
std::string counters_text(const EncoderCounters& c) {
  return counts_text<4>({{{"invalid", c.invalid_transitions},
                          {"jumps", c.implausible_jumps},
                          {"stale", c.stale_events},
                          {"read_errors", c.read_errors}}}) +
         // The serial link's (all 0 for the other backends: then nothing is printed).
         counts_text<4>({{{"link_errors", c.link_errors},
                          {"gaps", c.sequence_gaps},
                          {"resets", c.controller_resets},
                          {"reconnects", c.reconnects}}}) +
         // Several encoders per side (hal/side_wheels.hpp; 0 with one: nothing is printed).
         counts_text<2>({{{"slips", c.slip_events}, {"wheel_drops", c.wheel_drops}}});
}

}  // namespace

// print_status: one status line; `truth` is the simulation's newest sample (null: none).
void print_status(std::ostream& out, const loop::LoopSnapshot& s, double rate_hz,
                  const sim::TruthSample* truth) {
  char line[320];
  std::snprintf(line, sizeof line, "t=%7.2f s  x=%+8.4f m  y=%+8.4f m  th=%+8.2f deg  v=%+5.2f m/s",
                to_seconds(s.loop_time), s.pose.x, s.pose.y, wrap_angle(s.pose.theta) * kDegPerRad,
                s.v);
  out << line;
  if (truth != nullptr) {
    std::snprintf(line, sizeof line, "  err=%6.2f mm", truth->position_error() * 1e3);
    out << line;
  }
  char timing[96];
  std::snprintf(line, sizeof line, "  rate=%6.1f Hz  %s  missed=%llu  enc=%s", rate_hz,
                format_timing_status(timing, sizeof timing, s.stats),
                static_cast<unsigned long long>(s.stats.missed_deadlines),
                flags_text(s.encoder_flags).c_str());
  out << line << counters_text(s.encoder_counters);
  if (s.gyro.enabled) out << gyro_text(s.gyro);
  out << std::endl;
}

// print_final: the two lines at the stop: ticks, loop time, mean rate, missed deadlines; the
// final pose (and the simulation's truth and position error, when there is one).
void print_final(std::ostream& out, const loop::LoopSnapshot& s, const loop::LoopStats& st,
                 const sim::TruthSample* truth) {
  const double loop_s = to_seconds(s.loop_time);
  const double mean_rate = loop_s > 0 ? static_cast<double>(st.ticks) / loop_s : 0.0;
  out << "odometryd: stopped after " << st.ticks << " ticks (" << loop_s << " s of loop time, "
      << std::fixed << std::setprecision(1) << mean_rate << " Hz), missed deadlines "
      << st.missed_deadlines << "\n"
      << std::setprecision(4) << "odometryd: final pose x=" << s.pose.x << " m y=" << s.pose.y
      << " m theta=" << wrap_angle(s.pose.theta) * kDegPerRad << " deg";
  if (truth != nullptr) {
    out << "; ground truth x=" << truth->truth.x << " m y=" << truth->truth.y
        << " m theta=" << wrap_angle(truth->truth.theta) * kDegPerRad << " deg; position error "
        << std::setprecision(2) << truth->position_error() * 1e3 << " mm";
  }
  out << std::defaultfloat << std::setprecision(6) << std::endl;
}

}  // namespace odo::fw
