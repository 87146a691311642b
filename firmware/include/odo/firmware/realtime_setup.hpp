// Real-time set-up of the loop thread from the [realtime] config section, with a start-up report.
#pragma once

#include <iosfwd>

#include "odo/firmware/config.hpp"

namespace odo::fw {

// setup_realtime: applies `cfg` to the calling thread (the loop thread) and writes one line per
// part to `log`. Returns false, with the reason on `err`, when cfg.required is set and a
// requested part could not be applied. With virtual_time nothing is applied (simulation runs
// as fast as possible and must not hog a CPU at real-time priority).
bool setup_realtime(const RealtimeSection& cfg, bool virtual_time, std::ostream& log,
                    std::ostream& err);

}  // namespace odo::fw
