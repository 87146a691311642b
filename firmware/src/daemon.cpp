#include "odo/firmware/daemon.hpp"

#include <time.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstddef>
#include <cstdio>
#include <iomanip>
#include <mutex>
#include <ostream>
#include <thread>

#include <nlohmann/json.hpp>

#include "odo/firmware/calibration_reload.hpp"
#include "odo/firmware/calibration_store.hpp"
#include "odo/firmware/can_broadcast.hpp"
#include "odo/firmware/config.hpp"
#include "odo/firmware/realtime_setup.hpp"
#include "odo/firmware/rig.hpp"
#include "odo/firmware/selfcal_estimator.hpp"
#include "odo/firmware/state_persist.hpp"
#include "odo/firmware/timing_report.hpp"
#include "odo/firmware/watchdog.hpp"
#include "odo/hal/angle.hpp"
#include "odo/loop/loop.hpp"
#include "odo/sim/truth.hpp"
#include "ros2_output.hpp"

namespace odo::fw {
namespace {

struct BitName {
  std::uint32_t bit;
  const char* name;
};
constexpr BitName kEncoderFlagNames[] = {{kEncoderStaleLeft, "stale-left"},
                                         {kEncoderStaleRight, "stale-right"},
                                         {kEncoderInvalidTransition, "invalid-transition"},
                                         {kEncoderImplausibleJump, "implausible-jump"},
                                         {kEncoderReadError, "read-error"},
                                         {kEncoderLinkError, "link-error"},
                                         {kEncoderControllerReset, "controller-reset"},
                                         {kEncoderNoValidData, "no-valid-data(wrong-baud?)"}};
constexpr BitName kGyroFlagNames[] = {{kGyroStarting, "starting"},
                                      {kGyroStale, "stale"},
                                      {kGyroSaturated, "saturated"},
                                      {kGyroInvalid, "invalid"},
                                      {kGyroReadError, "read-error"}};

// bits_text: the names of the bits set in f, joined by '|'; "" when none is.
template <std::size_t N>
std::string bits_text(std::uint32_t f, const BitName (&names)[N]) {
  std::string s;
  for (const BitName& b : names) {
    if (f & b.bit) s += (s.empty() ? "" : "|") + std::string(b.name);
  }
  return s;
}

std::string flags_text(std::uint32_t f) {
  return f == 0 ? "ok" : bits_text(f, kEncoderFlagNames);
}

struct Count {
  const char* name;
  std::uint64_t value;
};

// counts_text: " (name=value ...)" of four event counters, "" while all are 0.
std::string counts_text(const std::array<Count, 4>& counts) {
  if (std::all_of(counts.begin(), counts.end(), [](const Count& c) { return c.value == 0; }))
    return {};
  std::string s = " (";
  for (std::size_t i = 0; i < counts.size(); ++i)
    s += (i > 0 ? " " : "") + std::string(counts[i].name) + "=" + std::to_string(counts[i].value);
  return s + ")";
}

// gyro_text: the status line's gyro part: what the fusion does this tick (the sample's flags
// when it has any, "non-finite" for a NaN/inf rate without one, else learning-bias or fusing),
// and the event counters once there is something to count.
std::string gyro_text(const loop::LoopGyroStatus& g) {
  std::string s = "  gyro=";
  if (g.gyro_flags != 0)
    s += bits_text(g.gyro_flags, kGyroFlagNames);
  else if ((g.fusion_flags & kFusionGyroFault) != 0)
    s += "non-finite";
  else
    s += g.bias_valid ? "fusing" : "learning-bias";
  const FusionCounters& c = g.fusion;
  return s + counts_text({{{"bumps", c.disagreements},
                           {"speed", c.speed_events},
                           {"accel", c.accel_events},
                           {"faults", c.gyro_faults}}});
}

// counters_text: the cumulative encoder fault counters, once there is something to count (a
// fault between two status lines would otherwise be invisible in the per-sample flags).
std::string counters_text(const EncoderCounters& c) {
  return counts_text({{{"invalid", c.invalid_transitions},
                       {"jumps", c.implausible_jumps},
                       {"stale", c.stale_events},
                       {"read_errors", c.read_errors}}}) +
         // The serial link's (all 0 for the other backends: then nothing is printed).
         counts_text({{{"link_errors", c.link_errors},
                       {"gaps", c.sequence_gaps},
                       {"resets", c.controller_resets},
                       {"reconnects", c.reconnects}}});
}

// print_status: one status line; `truth` is the simulation's newest sample (null: none).
void print_status(std::ostream& out, const loop::LoopSnapshot& s, double rate_hz,
                  const sim::TruthSample* truth) {
  char line[320];
  std::snprintf(line, sizeof line, "t=%7.2f s  x=%+8.4f m  y=%+8.4f m  th=%+8.2f deg  v=%+5.2f m/s",
                to_seconds(s.loop_time), s.pose.x, s.pose.y, wrap_angle(s.pose.theta) * kDegPerRad,
                s.v);
  out << line;
  if (truth != nullptr) {
    std::snprintf(line, sizeof line, "  err=%6.2f mm", truth->position_error() * 1e3);
    out << line;
  }
  char timing[96];
  std::snprintf(line, sizeof line, "  rate=%6.1f Hz  %s  missed=%llu  enc=%s", rate_hz,
                format_timing_status(timing, sizeof timing, s.stats),
                static_cast<unsigned long long>(s.stats.missed_deadlines),
                flags_text(s.encoder_flags).c_str());
  out << line << counters_text(s.encoder_counters);
  if (s.gyro.enabled) out << gyro_text(s.gyro);
  out << std::endl;
}

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

// StatusPrinter: a thread that prints one status line every `period` [s] from the loop's newest
// snapshot (and the simulation's truth, when there is one); the loop never waits for it.
class StatusPrinter {
 public:
  StatusPrinter(std::ostream& log, double period, loop::OdometryLoop& loop,
                sim::TruthRecorder* truth);
  ~StatusPrinter();
  StatusPrinter(const StatusPrinter&) = delete;
  StatusPrinter& operator=(const StatusPrinter&) = delete;
  // stop: ends and joins the thread (idempotent).
  void stop();

 private:
  void run();
  std::ostream& log_;
  double period_;
  loop::OdometryLoop& loop_;
  sim::TruthRecorder* truth_;
  std::mutex m_;
  std::condition_variable cv_;
  bool done_ = false;
  std::thread thread_;
};

// The README ("Gyro") documents gyro.flags by these bit values: they are part of --json.
static_assert(kGyroStale == 1 && kGyroSaturated == 2 && kGyroInvalid == 4 && kGyroReadError == 8 &&
                  kGyroStarting == 16,
              "gyro.flags bits changed: update README \"Gyro\"");

// gyro_json: the gyro and its fusion ([gyro]; README "Gyro").
nlohmann::json gyro_json(const loop::LoopGyroStatus& g) {
  nlohmann::json j;
  j["bumps_detected"] = g.fusion.disagreements;
  j["speed_events"] = g.fusion.speed_events;
  j["accel_events"] = g.fusion.accel_events;
  j["gyro_used_ticks"] = g.fusion.flagged_ticks;
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

// report_json: the --json object at exit.
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

}  // namespace

// ---- StatusPrinter ----

StatusPrinter::StatusPrinter(std::ostream& log, double period, loop::OdometryLoop& loop,
                             sim::TruthRecorder* truth)
    : log_(log), period_(period), loop_(loop), truth_(truth) {
  thread_ = std::thread([this] { run(); });
}

StatusPrinter::~StatusPrinter() {
  stop();
}

void StatusPrinter::stop() {
  if (!thread_.joinable()) return;
  {
    std::lock_guard lk(m_);
    done_ = true;
  }
  cv_.notify_all();
  thread_.join();
}

void StatusPrinter::run() {
  loop::LoopSnapshot s;
  sim::TruthSample truth;
  bool have_truth = false;
  std::uint64_t last_tick = 0;
  auto last = std::chrono::steady_clock::now();
  std::unique_lock lk(m_);
  const auto period = std::chrono::duration<double>(period_);
  while (!cv_.wait_for(lk, period, [&] { return done_; })) {
    if (!loop_.snapshots().latest(s)) continue;
    if (truth_ != nullptr && truth_->latest(truth)) have_truth = true;
    const auto now = std::chrono::steady_clock::now();
    const double dt = std::chrono::duration<double>(now - last).count();
    const double rate = dt > 0 ? static_cast<double>(s.tick - last_tick) / dt : 0.0;
    last = now;
    last_tick = s.tick;
    print_status(log_, s, rate, have_truth ? &truth : nullptr);
  }
}

// ---- Daemon ----

Daemon::Daemon(const DaemonOptions& o, std::ostream& out, std::ostream& err)
    : o_(o), out_(out), err_(err), log_(o.json ? err : out) {}

Daemon::~Daemon() = default;

int Daemon::fail(const std::string& message, int code) {
  err_ << "odometryd: " << message << "\n";
  return code;
}

int Daemon::configure() {
  Result<Config> cfg =
      o_.config_path.empty() ? Result<Config>(default_config()) : load_config(o_.config_path);
  if (!cfg) return fail(cfg.error().message);
  cfg_ = std::make_unique<Config>(std::move(cfg).value());
  auto kin = Kinematics::create(cfg_->robot);
  if (!kin) return fail(cfg_->source + ": robot: " + kin.error().message);
  // The store's corrections on top of the nominal robot (the rig keeps the nominal one).
  cal_ = std::make_unique<AppliedCalibration>(
      read_and_apply(cfg_->robot, cfg_->calibration.store, cfg_->calibration.backend));
  (cal_->state == calib::StoreStatus::kCorrupt ? err_ : log_)
      << "odometryd: " << cal_->report << "\n";
  auto calibrated = Kinematics::create(cal_->params);
  if (!calibrated) calibrated = *kin;
  auto rig = Rig::create(*cfg_, *kin, o_.virtual_time);
  if (!rig) return fail(rig.error().message);
  rig_ = std::make_unique<Rig>(std::move(rig).value());
  loop::LoopConfig lc;
  lc.rate_hz = cfg_->loop.rate_hz;
  lc.error_model = cfg_->error_model;
  lc.calibration = cal_->state;
  EncoderSource* encoder = &rig_->encoder();
  if (cfg_->selfcal.enabled) {  // the loop reads through the self-calibration recorder
    auto sc = SelfCalLink::create(*cfg_, calibrated->params(), *encoder, log_);
    if (!sc) return fail(cfg_->source + ": " + sc.error().message);
    selfcal_ = std::move(sc).value();
    encoder = &selfcal_->encoder();
  }
  lc.gyrodometry = rig_->gyrodometry();
  lc.gyro_scale_estimation = cfg_->gyro.scale_estimation;
  // CAN controllers send on their own schedule: the reference reading waits for their first
  // frames (at most the stale timeout), so that it is their own counters (a resume needs them).
  if (cfg_->encoder.backend == EncoderKind::kCan &&
      cfg_->can_encoder.bus == CanEncoderBus::kSocketCan)
    lc.start_wait = from_seconds(cfg_->can_encoder.timeout);
  // Likewise a microcontroller on a serial line (an Arduino reboots when its port opens).
  if (cfg_->encoder.backend == EncoderKind::kSerial && cfg_->serial.link == SerialLink::kTty)
    lc.start_wait = from_seconds(cfg_->serial.start_wait);
  auto created = loop::OdometryLoop::create(lc, *calibrated, *encoder, rig_->clock(), rig_->gyro());
  if (!created) return fail(cfg_->source + ": " + created.error().message);
  loop_ = std::move(created).value();
  if (sim::TruthRecorder* t = rig_->truth()) loop_->add_observer(t);
  // CAN pose broadcast ([can], --can-log).
  auto can = CanLink::create(cfg_->can, cfg_->loop.rate_hz, *loop_, o_.can_log, o_.virtual_time);
  if (!can) return fail(cfg_->source + ": " + can.error().message);
  can_ = std::move(can).value();
  // ROS 2 output ([ros2] enabled): an observer of the loop plus the DDS thread.
  auto ros2 = Ros2Output::create(cfg_->ros2.get(), cfg_->loop.rate_hz, cfg_->error_model, *loop_);
  if (!ros2) return fail(cfg_->source + ": " + ros2.error().message);
  ros2_ = std::move(ros2).value();
  if (selfcal_) selfcal_->attach(*loop_, can_.get());
  reloader_ = std::make_unique<CalibrationReloader>(
      loop_->commands(), cfg_->robot, cfg_->calibration.store, cfg_->calibration.backend, log_);
  if (o_.reload != nullptr) reloader_->start(*o_.reload);
  // Pose that survives restarts: not in virtual time (its clock restarts with the process).
  if (!o_.virtual_time)
    resume_ = std::make_unique<ResumeWiring>(prepare_resume(*cfg_, *loop_, cal_->sequence, log_));
  report_start(calibrated->params());
  return 0;
}

void Daemon::report_start(const KinematicParams& p) {
  log_ << "odometryd: config " << cfg_->source << "\n"
       << "odometryd: encoders: " << rig_->describe() << "\n"
       << "odometryd: kinematics: Dn=" << p.wheel_diameter << " m, Ce=" << p.counts_per_rev
       << ", n=" << p.gear_ratio << ", b=" << p.wheelbase << " m, c_l=" << p.c_l
       << ", c_r=" << p.c_r
       << (cal_->state == calib::StoreStatus::kOk ? " (calibrated)\n"
                                                  : " (nominal values from the config)\n")
       << "odometryd: can: " << (can_ ? can_->describe() : std::string("off")) << "\n"
       << (ros2_ ? "odometryd: ros2: " + ros2_->describe() + "\n" : std::string())
       << (selfcal_ ? "odometryd: selfcal: " + selfcal_->describe() + "\n" : std::string())
       << "odometryd: loop " << cfg_->loop.rate_hz << " Hz on "
       << (o_.virtual_time ? "virtual time" : "CLOCK_MONOTONIC") << std::endl;
}

int Daemon::run(std::atomic<bool>& stop) {
  double duration = o_.duration;
  if (duration <= 0.0 && o_.virtual_time) duration = rig_->scenario_duration() + 1.0;
  // Status printer: its own thread, so the loop never blocks on a terminal or pipe.
  std::unique_ptr<StatusPrinter> status;
  if (!o_.quiet && cfg_->loop.status_period > 0.0 && !o_.virtual_time)
    status = std::make_unique<StatusPrinter>(log_, cfg_->loop.status_period, *loop_, rig_->truth());
  // systemd: READY=1 after the first tick, WATCHDOG=1 only while the tick counter advances.
  auto watchdog = LoopWatchdog::from_environment([&l = *loop_] { return l.heartbeat(); });
  if (watchdog->enabled()) {
    log_ << "odometryd: systemd notify: on, watchdog "
         << (watchdog->interval() > 0 ? std::to_string(to_seconds(watchdog->interval())) + " s"
                                      : std::string("off"))
         << std::endl;
  }
  // The DDS thread, like the status thread, starts before the real-time set-up (normal
  // scheduling); it only reads the loop's snapshots.
  if (ros2_) {
    auto started = ros2_->start(o_.virtual_time, cfg_->realtime.required, log_);
    if (!started) return fail(started.error().message, 1);
  }
  // The loop runs on this thread: real-time set-up after the status thread started, so that
  // thread keeps normal scheduling.
  if (!setup_realtime(cfg_->realtime, o_.virtual_time, log_, err_)) return 1;
  watchdog->start();
  if (can_) {
    timespec wall{};
    clock_gettime(CLOCK_REALTIME, &wall);
    can_->start(static_cast<std::int64_t>(wall.tv_sec) * kNsPerSecond + wall.tv_nsec);
  }
  if (resume_ && resume_->persister) {
    resume_->persister->start(
        log_, resume_->offered ? std::nullopt : std::optional(resume_->reason), resume_->note);
  }
  if (selfcal_) selfcal_->start();
  loop_->run(from_seconds(duration), stop);
  if (selfcal_) selfcal_->stop();
  if (resume_ && resume_->persister) resume_->persister->stop();
  // Clean stop (signal or end of --duration): the final pose and a status frame that says so.
  if (can_) can_->finish(loop_->snapshot());
  if (ros2_) ros2_->stop();
  watchdog->stop();
  reloader_->stop();
  return 0;
}

void Daemon::report() {
  const loop::LoopSnapshot& s = loop_->snapshot();
  const loop::LoopStats& st = loop_->stats();
  const sim::TruthSample* truth = rig_->truth() ? &rig_->truth()->newest() : nullptr;
  const double loop_s = to_seconds(s.loop_time);
  const double mean_rate = loop_s > 0 ? static_cast<double>(st.ticks) / loop_s : 0.0;
  log_ << "odometryd: stopped after " << st.ticks << " ticks (" << loop_s << " s of loop time, "
       << std::fixed << std::setprecision(1) << mean_rate << " Hz), missed deadlines "
       << st.missed_deadlines << "\n"
       << std::setprecision(4) << "odometryd: final pose x=" << s.pose.x << " m y=" << s.pose.y
       << " m theta=" << wrap_angle(s.pose.theta) * kDegPerRad << " deg";
  if (truth != nullptr) {
    log_ << "; ground truth x=" << truth->truth.x << " m y=" << truth->truth.y
         << " m theta=" << wrap_angle(truth->truth.theta) * kDegPerRad << " deg; position error "
         << std::setprecision(2) << truth->position_error() * 1e3 << " mm";
  }
  log_ << std::defaultfloat << std::setprecision(6) << std::endl;
  if (o_.stats) print_timing_stats(log_, st, loop_->period());
  if (!o_.json) return;
  nlohmann::json j = report_json(s, st, truth, can_.get());
  if (ros2_) j["ros2"] = ros2_->json();
  if (resume_) {
    const loop::ResumeReason why = resume_reason(*resume_, *loop_);
    j["resume"] = {
        {"resumed", why == loop::ResumeReason::kResumed},
        {"reason", std::string(loop::resume_reason_name(why))},
        {"gap",
         why == loop::ResumeReason::kResumed ? to_seconds(loop_->resume_decision().gap) : 0.0},
        // With the pose or from a fresh one (restore_gyro): only a decision the loop made.
        {"gyro_restored", resume_->offered && loop_->resume_decision().gyro_restored}};
  }
  if (selfcal_) j["selfcal"] = selfcal_json(selfcal_->estimator().counters());
  out_ << j.dump() << std::endl;
}

int run_daemon(const DaemonOptions& o, std::atomic<bool>& stop, std::ostream& out,
               std::ostream& err) {
  Daemon d(o, out, err);
  if (const int rc = d.configure(); rc != 0) return rc;
  if (const int rc = d.run(stop); rc != 0) return rc;
  d.report();
  return 0;
}

}  // namespace odo::fw
