#include "odo/firmware/realtime_setup.hpp"

#include <ostream>

#include "odo/drivers/realtime.hpp"
#include "realtime_report.hpp"

namespace odo::fw {

bool setup_realtime(const RealtimeSection& cfg, bool virtual_time, std::ostream& log,
                    std::ostream& err) {
  if (virtual_time) {
    log << "odometryd: realtime: not applied (virtual time runs as fast as possible)\n";
    return true;
  }
  drivers::RealtimeRequest r;
  r.fifo_priority = cfg.priority;
  r.lock_memory = cfg.lock_memory;
  r.cpu = cfg.cpu;
  r.prefault_stack = static_cast<std::size_t>(cfg.prefault_stack);
  r.cpu_latency_us = cfg.cpu_latency_us;
  bool ok = true;
  for (const drivers::RealtimeItem& it : drivers::apply_realtime(r))
    ok = report_realtime("realtime", it, cfg.required, log, err) && ok;
  log.flush();
  return ok;
}

bool report_realtime(std::string_view who, const drivers::RealtimeItem& it, bool required,
                     std::ostream& log, std::ostream& err) {
  log << "odometryd: " << who << ": " << it.what << ": ";
  switch (it.outcome) {
    case drivers::RtOutcome::kApplied:
      log << "applied\n";
      return true;
    case drivers::RtOutcome::kOff:
      log << it.detail << "\n";
      return true;
    case drivers::RtOutcome::kNotPermitted:
    case drivers::RtOutcome::kFailed:
      break;
  }
  log << "NOT APPLIED: " << it.detail << (required ? "" : "; continuing") << "\n";
  if (!required) return true;
  err << "odometryd: " << who << ": " << it.what << " could not be applied and [realtime] "
      << "required = true: refusing to start (" << it.detail << ")\n";
  return false;
}

}  // namespace odo::fw
