#include "odo/firmware/timing_report.hpp"

#include <cstdio>
#include <ostream>

namespace odo::fw {
namespace {

double us(TimeNs ns) {
  return static_cast<double>(ns) * 1e-3;
}

void row(std::ostream& out, const char* name, const loop::TimingSummary& s) {
  char line[160];
  std::snprintf(line, sizeof line, "  %-16s %10.1f %10.1f %10.1f %10.1f %10.1f\n", name, us(s.min),
                us(s.mean), us(s.p99), us(s.p999), us(s.max));
  out << line;
}

}  // namespace

void print_timing_stats(std::ostream& out, const loop::LoopStats& st, TimeNs period) {
  char head[200];
  std::snprintf(head, sizeof head,
                "odometryd: timing over %llu ticks (period %.3f ms), missed deadlines %llu\n"
                "  %-16s %10s %10s %10s %10s %10s  [us]\n",
                static_cast<unsigned long long>(st.ticks), us(period) * 1e-3,
                static_cast<unsigned long long>(st.missed_deadlines), "", "min", "mean", "p99",
                "p99.9", "max");
  out << head;
  row(out, "wake-up latency", st.wakeup_latency);
  row(out, "compute time", st.compute_time);
  out.flush();
}

const char* format_timing_status(char* buf, std::size_t size, const loop::LoopStats& st) noexcept {
  // The percentiles are summarised every kSummaryTicks ticks: until the first summary there are
  // none, and "-" says so (a 0 would read as a measured 0 us).
  char lat[24] = "-", cmp[24] = "-";
  if (st.wakeup_latency.count > 0)
    std::snprintf(lat, sizeof lat, "%.0f", us(st.wakeup_latency.p99));
  if (st.compute_time.count > 0) std::snprintf(cmp, sizeof cmp, "%.1f", us(st.compute_time.p99));
  std::snprintf(buf, size, "lat p99/max=%s/%.0f us  cmp p99=%s us", lat, us(st.wakeup_latency_max),
                cmp);
  return buf;
}

}  // namespace odo::fw
