#include "odo/firmware/realtime_setup.hpp"

#include <ostream>

#include "odo/drivers/realtime.hpp"

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
  bool ok = true;
  for (const drivers::RealtimeItem& it : drivers::apply_realtime(r)) {
    log << "odometryd: realtime: " << it.what << ": ";
    switch (it.outcome) {
      case drivers::RtOutcome::kApplied:
        log << "applied\n";
        break;
      case drivers::RtOutcome::kOff:
        log << it.detail << "\n";
        break;
      case drivers::RtOutcome::kNotPermitted:
      case drivers::RtOutcome::kFailed:
        log << "NOT APPLIED: " << it.detail << (cfg.required ? "" : "; continuing") << "\n";
        if (cfg.required) {
          err << "odometryd: realtime: " << it.what << " could not be applied and [realtime] "
              << "required = true: refusing to start (" << it.detail << ")\n";
          ok = false;
        }
        break;
    }
  }
  log.flush();
  return ok;
}

}  // namespace odo::fw
