// The start-up report of one real-time part applied to some thread (the loop's, the ROS 2
// publish thread's). Private to firmware/.
#pragma once

#include <iosfwd>
#include <string_view>

#include "odo/drivers/realtime.hpp"

namespace odo::fw {

// report_realtime: one start-up line "odometryd: <who>: <what>: applied | ... | NOT APPLIED: why"
// for a part applied to some thread; false (with the reason on err) when it was requested, not
// applied, and required.
bool report_realtime(std::string_view who, const drivers::RealtimeItem& it, bool required,
                     std::ostream& log, std::ostream& err);

}  // namespace odo::fw
