#include "status_json.hpp"

#include <string>

#include "odo/firmware/can_link.hpp"
#include "odo/firmware/selfcal_estimator.hpp"
#include "odo/firmware/state_persist.hpp"
#include "odo/hal/angle.hpp"
#include "odo/hal/gyro.hpp"
#include "odo/loop/loop.hpp"
#include "odo/sim/truth.hpp"

namespace odo::fw {
namespace {

nlohmann::json timing_json(const loop::TimingSummary& t) {
  return {{"min", to_seconds(t.min)},
          {"mean", to_seconds(t.mean)},
          {"p99", to_seconds(t.p99)},
          {"p999", to_seconds(t.p999)},
          {"max", to_seconds(t.max)}};
}

nlohmann::json can_json(const CanLink& can) {
  const CanBroadcastCounters& c = can.counters();
  return {{"sent", c.sent},
          {"dropped_queue_full", c.dropped_queue_full},
          {"dropped_link_down", c.dropped_link_down},
          {"dropped_error", c.dropped_error},
          {"set_pose_applied", c.set_pose_applied},
          {"set_pose_rejected", c.set_pose_rejected},
          {"log_written", can.log_written()},
          {"log_dropped", can.log_dropped()}};
}

// The README ("Gyro") documents gyro.flags by these bit values: they are part of --json.
static_assert(kGyroStale == 1 && kGyroSaturated == 2 && kGyroInvalid == 4 && kGyroReadError == 8 &&
                  kGyroStarting == 16,
              "gyro.flags bits changed: update README \"Gyro\"");

// gyro_json: the gyro and its fusion ([gyro]; README "Gyro").
nlohmann::json gyro_json(const loop::LoopGyroStatus& g) {
  nlohmann::json j;
  j["disagreements"] = g.fusion.disagreements;
  j["speed_events"] = g.fusion.speed_events;
  j["accel_events"] = g.fusion.accel_events;
  j["gyro_used_ticks"] = g.fusion.gyro_used_ticks;
  j["faults"] = g.fusion.gyro_faults;
  j["bias"] = g.bias;
  j["bias_valid"] = g.bias_valid;
  j["scale"] = g.scale;
  j["flags"] = g.gyro_flags;
  j["samples"] = g.gyro.samples;
  j["stale_events"] = g.gyro.stale_events;
  j["saturated"] = g.gyro.saturated;
  j["invalid"] = g.gyro.invalid;
  j["read_errors"] = g.gyro.read_errors;
  return j;
}

}  // namespace

nlohmann::json report_json(const loop::LoopSnapshot& s, const loop::LoopStats& st,
                           const sim::TruthSample* truth, const CanLink* can) {
  nlohmann::json j;
  j["x"] = s.pose.x;
  j["y"] = s.pose.y;
  j["theta"] = wrap_angle(s.pose.theta);
  j["theta_cumulative"] = s.pose.theta;
  j["distance"] = s.distance;
  j["ticks"] = st.ticks;
  j["loop_time"] = to_seconds(s.loop_time);
  j["missed_deadlines"] = st.missed_deadlines;
  j["wakeup_latency_max"] = to_seconds(st.wakeup_latency_max);
  j["timing"]["wakeup_latency"] = timing_json(st.wakeup_latency);
  j["timing"]["compute_time"] = timing_json(st.compute_time);
  j["encoder_flags"] = s.encoder_flags;
  j["invalid_transitions"] = s.encoder_counters.invalid_transitions;
  j["implausible_jumps"] = s.encoder_counters.implausible_jumps;
  j["stale_events"] = s.encoder_counters.stale_events;
  j["read_errors"] = s.encoder_counters.read_errors;
  j["link_errors"] = s.encoder_counters.link_errors;
  j["sequence_gaps"] = s.encoder_counters.sequence_gaps;
  j["controller_resets"] = s.encoder_counters.controller_resets;
  j["reconnects"] = s.encoder_counters.reconnects;
  j["calibration_state"] = static_cast<int>(s.calibration_state);
  if (s.gyro.enabled) j["gyro"] = gyro_json(s.gyro);
  if (can != nullptr) j["can"] = can_json(*can);
  if (truth != nullptr) {
    j["truth"] = {
        {"x", truth->truth.x}, {"y", truth->truth.y}, {"theta", wrap_angle(truth->truth.theta)}};
    j["position_error"] = truth->position_error();
  }
  return j;
}

nlohmann::json side_wheels_json(const loop::LoopSnapshot& s, int wheels_per_side) {
  // The gyro's intervals opened by a slip are here, not in "gyro": with one encoder per side
  // the --json object stays as it was.
  return {{"wheels_per_side", wheels_per_side},
          {"slip_events", s.encoder_counters.slip_events},
          {"wheel_drops", s.encoder_counters.wheel_drops},
          {"gyro_slip_events", s.gyro.fusion.slip_events}};
}

nlohmann::json resume_json(const ResumeWiring& resume, const loop::OdometryLoop& loop) {
  const loop::ResumeReason why = resume_reason(resume, loop);
  return {
      {"resumed", why == loop::ResumeReason::kResumed},
      {"reason", std::string(loop::resume_reason_name(why))},
      {"gap", why == loop::ResumeReason::kResumed ? to_seconds(loop.resume_decision().gap) : 0.0},
      // With the pose or from a fresh one (restore_gyro): only a decision the loop made.
      {"gyro_restored", resume.offered && loop.resume_decision().gyro_restored}};
}

nlohmann::json selfcal_json(const SelfCalCounters& c) {
  nlohmann::json j = {{"fixes_received", c.fixes_received},
                      {"fixes_dropped", c.fixes_dropped},
                      {"fixes_rejected", c.fixes_rejected},
                      {"fits", c.fits},
                      {"fit_errors", c.fit_errors},
                      {"accepted", c.accepted},
                      {"written", c.written},
                      {"store_errors", c.store_errors},
                      {"segments", c.segments}};
  if (c.last) {
    j["last"] = {{"c_l", c.last->estimate.c_l},
                 {"c_r", c.last->estimate.c_r},
                 {"wheelbase", c.last->estimate.wheelbase},
                 {"verdict", calib::verdict_name(c.last->verdict)}};
  }
  return j;
}

}  // namespace odo::fw
