// The status line and the final lines of odometryd (README "odometryd"): text only, written to
// a stream the caller owns; no thread (StatusPrinter's thread calls print_status). The flags'
// names are hal's tables (kEncoderFlagNames, kGyroFlagNames). Private to firmware/.
#pragma once

#include <iosfwd>

#include "odo/loop/loop.hpp"
#include "odo/sim/truth.hpp"

namespace odo::fw {

// print_status: one status line; rate_hz = ticks per second [Hz] since the previous line;
// `truth` is the simulation's newest sample (null: none).
void print_status(std::ostream& out, const loop::LoopSnapshot& s, double rate_hz,
                  const sim::TruthSample* truth);

// print_final: the lines at the stop (ticks, mean rate, final pose; truth and error when given).
void print_final(std::ostream& out, const loop::LoopSnapshot& s, const loop::LoopStats& st,
                 const sim::TruthSample* truth);

}  // namespace odo::fw
