// The --json object of odometryd at exit (README "odometryd"): its keys and values from the
// loop's final snapshot and the parts' counters; formatting only, no thread. Private to
// firmware/.
#pragma once

#include <nlohmann/json.hpp>

#include "odo/loop/loop.hpp"
#include "odo/sim/truth.hpp"

namespace odo::fw {

class CanLink;
struct ResumeWiring;
struct SelfCalCounters;

// report_json: the --json object at exit without its "ros2", "resume" and "selfcal" parts;
// `truth` and `can` may be null (no simulation truth, no CAN link).
nlohmann::json report_json(const loop::LoopSnapshot& s, const loop::LoopStats& st,
                           const sim::TruthSample* truth, const CanLink* can);

// side_wheels_json: the "wheels" object of several encoders per side (encoder.wheels_per_side
// > 1): their count, the combiner's event counters and the gyro's intervals opened by a slip
// (0 without a gyro).
nlohmann::json side_wheels_json(const loop::LoopSnapshot& s, int wheels_per_side);

// resume_json: the "resume" object: whether the persisted pose was taken, and why.
nlohmann::json resume_json(const ResumeWiring& resume, const loop::OdometryLoop& loop);

// selfcal_json: the "selfcal" object: the self-calibration's counters and last result.
nlohmann::json selfcal_json(const SelfCalCounters& c);

}  // namespace odo::fw
