#include "odo/firmware/daemon.hpp"

#include <time.h>

#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <iomanip>
#include <mutex>
#include <numbers>
#include <ostream>
#include <thread>

#include <nlohmann/json.hpp>

#include "odo/firmware/calibration_store.hpp"
#include "odo/firmware/calibration_reload.hpp"
#include "odo/firmware/can_broadcast.hpp"
#include "odo/firmware/config.hpp"
#include "odo/loop/loop.hpp"
#include "odo/firmware/realtime_setup.hpp"
#include "odo/firmware/rig.hpp"
#include "odo/firmware/timing_report.hpp"
#include "odo/firmware/watchdog.hpp"

namespace odo::fw {
namespace {

constexpr double kRadToDeg = 180.0 / std::numbers::pi;

std::string flags_text(std::uint32_t f) {
  if (f == 0) return "ok";
  std::string s;
  auto add = [&](std::uint32_t bit, const char* name) {
    if (f & bit) s += (s.empty() ? "" : "|") + std::string(name);
  };
  add(kEncoderStaleLeft, "stale-left");
  add(kEncoderStaleRight, "stale-right");
  add(kEncoderInvalidTransition, "invalid-transition");
  add(kEncoderImplausibleJump, "implausible-jump");
  add(kEncoderReadError, "read-error");
  return s;
}

double position_error(const loop::LoopSnapshot& s) {
  return std::hypot(s.pose.x - s.truth.x, s.pose.y - s.truth.y);
}

void print_status(std::ostream& out, const loop::LoopSnapshot& s, double rate_hz) {
  char line[320];
  std::snprintf(line, sizeof line, "t=%7.2f s  x=%+8.4f m  y=%+8.4f m  th=%+8.2f deg  v=%+5.2f m/s",
                to_seconds(s.loop_time), s.pose.x, s.pose.y, wrap_angle(s.pose.theta) * kRadToDeg,
                s.v);
  out << line;
  if (s.has_truth) {
    std::snprintf(line, sizeof line, "  err=%6.2f mm", position_error(s) * 1e3);
    out << line;
  }
  char timing[96];
  std::snprintf(line, sizeof line, "  rate=%6.1f Hz  %s  missed=%llu  enc=%s", rate_hz,
                format_timing_status(timing, sizeof timing, s.stats),
                static_cast<unsigned long long>(s.stats.missed_deadlines),
                flags_text(s.encoder_flags).c_str());
  out << line;
  // Cumulative encoder fault counters, once there is something to count (a fault between two
  // status lines would otherwise be invisible in the per-sample flags).
  const EncoderCounters& c = s.encoder_counters;
  if (c.invalid_transitions + c.implausible_jumps + c.stale_events + c.read_errors > 0) {
    std::snprintf(line, sizeof line, " (invalid=%llu jumps=%llu stale=%llu read_errors=%llu)",
                  static_cast<unsigned long long>(c.invalid_transitions),
                  static_cast<unsigned long long>(c.implausible_jumps),
                  static_cast<unsigned long long>(c.stale_events),
                  static_cast<unsigned long long>(c.read_errors));
    out << line;
  }
  out << std::endl;
}

}  // namespace

int run_daemon(const DaemonOptions& o, std::atomic<bool>& stop, std::ostream& out,
               std::ostream& err) {
  // Human-readable progress goes to stderr when stdout carries JSON.
  std::ostream& log = o.json ? err : out;
  Result<Config> cfg =
      o.config_path.empty() ? Result<Config>(default_config()) : load_config(o.config_path);
  if (!cfg) {
    err << "odometryd: " << cfg.error().message << "\n";
    return 2;
  }
  auto kin = Kinematics::create(cfg->robot);
  if (!kin) {
    err << "odometryd: " << cfg->source << ": robot: " << kin.error().message << "\n";
    return 2;
  }
  // The store's corrections on top of the nominal robot (the rig keeps the nominal one).
  const AppliedCalibration cal =
      read_and_apply(cfg->robot, cfg->calibration.store, cfg->calibration.backend);
  (cal.state == 2 ? err : log) << "odometryd: " << cal.report << "\n";
  auto calibrated = Kinematics::create(cal.params);
  if (!calibrated) calibrated = *kin;
  auto rig = Rig::create(*cfg, *kin, o.virtual_time);
  if (!rig) {
    err << "odometryd: " << rig.error().message << "\n";
    return 2;
  }
  loop::LoopConfig lc;
  lc.rate_hz = cfg->loop.rate_hz;
  lc.error_model = cfg->error_model;
  auto created = loop::OdometryLoop::create(lc, *calibrated, rig->encoder(), rig->clock());
  if (!created) {
    err << "odometryd: " << cfg->source << ": " << created.error().message << "\n";
    return 2;
  }
  std::unique_ptr<loop::OdometryLoop> loop = std::move(created).value();
  if (loop::TickObserver* t = rig->truth_observer()) loop->add_observer(t);
  CalibrationHandover cal_handover(cal.state);
  cal_handover.attach(loop.get());
  loop->add_observer(&cal_handover);
  // CAN pose broadcast ([can], --can-log): an observer after the calibration hand-over, so the
  // status frame carries this tick's calibration state.
  auto can_link = CanLink::create(cfg->can, cfg->loop.rate_hz, *loop, o.can_log, o.virtual_time);
  if (!can_link) {
    err << "odometryd: " << cfg->source << ": " << can_link.error().message << "\n";
    return 2;
  }
  std::unique_ptr<CanLink> can = std::move(can_link).value();
  CalibrationReloader reloader(cal_handover, cfg->robot, cfg->calibration.store,
                               cfg->calibration.backend, log);
  if (o.reload != nullptr) reloader.start(*o.reload);

  const KinematicParams& p = calibrated->params();
  log << "odometryd: config " << cfg->source << "\n"
      << "odometryd: encoders: " << rig->describe() << "\n"
      << "odometryd: kinematics: Dn=" << p.wheel_diameter << " m, Ce=" << p.counts_per_rev
      << ", n=" << p.gear_ratio << ", b=" << p.wheelbase << " m, c_l=" << p.c_l << ", c_r=" << p.c_r
      << (cal.state == 1 ? " (calibrated)\n" : " (nominal values from the config)\n")
      << "odometryd: can: " << (can ? can->describe() : std::string("off")) << "\n"
      << "odometryd: loop " << cfg->loop.rate_hz << " Hz on "
      << (o.virtual_time ? "virtual time" : "CLOCK_MONOTONIC") << std::endl;

  double duration = o.duration;
  if (duration <= 0.0 && o.virtual_time) duration = rig->scenario_duration() + 1.0;

  // Status printer: its own thread, so the loop never blocks on a terminal or pipe.
  std::mutex m;
  std::condition_variable cv;
  bool done = false;
  std::thread status;
  const bool want_status = !o.quiet && cfg->loop.status_period > 0.0 && !o.virtual_time;
  if (want_status) {
    status = std::thread([&] {
      loop::LoopSnapshot s;
      std::uint64_t last_tick = 0;
      auto last = std::chrono::steady_clock::now();
      std::unique_lock lk(m);
      const auto period = std::chrono::duration<double>(cfg->loop.status_period);
      while (!cv.wait_for(lk, period, [&] { return done; })) {
        if (!loop->snapshots().latest(s)) continue;
        const auto now = std::chrono::steady_clock::now();
        const double dt = std::chrono::duration<double>(now - last).count();
        const double rate = dt > 0 ? static_cast<double>(s.tick - last_tick) / dt : 0.0;
        last = now;
        last_tick = s.tick;
        print_status(log, s, rate);
      }
    });
  }

  auto stop_status = [&] {
    if (!status.joinable()) return;
    {
      std::lock_guard lk(m);
      done = true;
    }
    cv.notify_all();
    status.join();
  };

  // systemd: READY=1 after the first tick, WATCHDOG=1 only while the tick counter advances.
  auto watchdog = LoopWatchdog::from_environment([&l = *loop] { return l.heartbeat(); });
  if (watchdog->enabled()) {
    log << "odometryd: systemd notify: on, watchdog "
        << (watchdog->interval() > 0 ? std::to_string(to_seconds(watchdog->interval())) + " s"
                                     : std::string("off"))
        << std::endl;
  }
  // The loop runs on this thread: real-time set-up after the status thread started, so that
  // thread keeps normal scheduling.
  if (!setup_realtime(cfg->realtime, o.virtual_time, log, err)) {
    stop_status();
    return 1;
  }
  watchdog->start();
  if (can) {
    timespec wall{};
    clock_gettime(CLOCK_REALTIME, &wall);
    can->start(static_cast<std::int64_t>(wall.tv_sec) * kNsPerSecond + wall.tv_nsec);
  }
  loop->run(from_seconds(duration), stop);
  // Clean stop (signal or end of --duration): the final pose and a status frame that says so.
  if (can) can->finish(loop->snapshot());
  watchdog->stop();
  reloader.stop();
  stop_status();

  const loop::LoopSnapshot& s = loop->snapshot();
  const loop::LoopStats& st = loop->stats();
  const double loop_s = to_seconds(s.loop_time);
  const double mean_rate = loop_s > 0 ? static_cast<double>(st.ticks) / loop_s : 0.0;
  log << "odometryd: stopped after " << st.ticks << " ticks (" << loop_s << " s of loop time, "
      << std::fixed << std::setprecision(1) << mean_rate << " Hz), missed deadlines "
      << st.missed_deadlines << "\n"
      << std::setprecision(4) << "odometryd: final pose x=" << s.pose.x << " m y=" << s.pose.y
      << " m theta=" << wrap_angle(s.pose.theta) * kRadToDeg << " deg";
  if (s.has_truth) {
    log << "; ground truth x=" << s.truth.x << " m y=" << s.truth.y
        << " m theta=" << wrap_angle(s.truth.theta) * kRadToDeg << " deg; position error "
        << std::setprecision(2) << position_error(s) * 1e3 << " mm";
  }
  log << std::defaultfloat << std::setprecision(6) << std::endl;
  if (o.stats) print_timing_stats(log, st, loop->period());

  if (o.json) {
    nlohmann::json j;
    j["x"] = s.pose.x;
    j["y"] = s.pose.y;
    j["theta"] = wrap_angle(s.pose.theta);
    j["theta_cumulative"] = s.pose.theta;
    j["distance"] = s.distance;
    j["ticks"] = st.ticks;
    j["loop_time"] = loop_s;
    j["missed_deadlines"] = st.missed_deadlines;
    j["wakeup_latency_max"] = to_seconds(st.wakeup_latency_max);
    for (const auto& [name, t] : {std::pair{"wakeup_latency", &st.wakeup_latency},
                                  std::pair{"compute_time", &st.compute_time}}) {
      j["timing"][name] = {{"min", to_seconds(t->min)},
                           {"mean", to_seconds(t->mean)},
                           {"p99", to_seconds(t->p99)},
                           {"p999", to_seconds(t->p999)},
                           {"max", to_seconds(t->max)}};
    }
    j["encoder_flags"] = s.encoder_flags;
    j["invalid_transitions"] = s.encoder_counters.invalid_transitions;
    j["implausible_jumps"] = s.encoder_counters.implausible_jumps;
    j["stale_events"] = s.encoder_counters.stale_events;
    j["read_errors"] = s.encoder_counters.read_errors;
    j["calibration_state"] = s.calibration_state;
    if (can) {
      const CanBroadcastCounters& c = can->counters();
      j["can"] = {{"sent", c.sent},
                  {"dropped_queue_full", c.dropped_queue_full},
                  {"dropped_link_down", c.dropped_link_down},
                  {"dropped_error", c.dropped_error},
                  {"set_pose_applied", c.set_pose_applied},
                  {"set_pose_rejected", c.set_pose_rejected},
                  {"log_written", can->log_written()},
                  {"log_dropped", can->log_dropped()}};
    }
    if (s.has_truth) {
      j["truth"] = {{"x", s.truth.x}, {"y", s.truth.y}, {"theta", wrap_angle(s.truth.theta)}};
      j["position_error"] = position_error(s);
    }
    out << j.dump() << std::endl;
  }
  return 0;
}

}  // namespace odo::fw
