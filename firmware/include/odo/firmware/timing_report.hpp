// Text forms of the loop's timing statistics: the `odometryd --stats` table and the fragment of
// the status line.
#pragma once

#include <cstddef>
#include <iosfwd>

#include "odo/loop/loop.hpp"

namespace odo::fw {

// print_timing_stats: the table of wake-up latency and compute time (min, mean, p99, p99.9,
// max in microseconds) and the missed deadlines, for a loop of period `period` [ns].
void print_timing_stats(std::ostream& out, const loop::LoopStats& st, TimeNs period);

// format_timing_status: "lat p99/max=12/80 us  cmp p99=4.0 us" into buf (no allocation), "-" for a
// p99 not summarised yet (the first kSummaryTicks ticks); returns buf.
const char* format_timing_status(char* buf, std::size_t size, const loop::LoopStats& st) noexcept;

}  // namespace odo::fw
