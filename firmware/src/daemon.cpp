#include "odo/firmware/daemon.hpp"

#include <time.h>

#include <optional>
#include <ostream>
#include <string>

#include <nlohmann/json.hpp>

#include "odo/firmware/calibration_reload.hpp"
#include "odo/firmware/calibration_store.hpp"
#include "odo/firmware/can_link.hpp"
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
#include "status_json.hpp"
#include "status_line.hpp"
#include "status_printer.hpp"

namespace odo::fw {

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
  auto can = CanLink::create(*cfg_, *loop_, o_.can_log, o_.virtual_time);
  if (!can) return fail(can.error().message);
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
  print_final(log_, s, st, truth);
  if (o_.stats) print_timing_stats(log_, st, loop_->period());
  if (!o_.json) return;
  nlohmann::json j = report_json(s, st, truth, can_.get());
  if (cfg_->encoder.side.wheels_per_side > 1)
    j["wheels"] = side_wheels_json(s, cfg_->encoder.side.wheels_per_side);
  if (ros2_) j["ros2"] = ros2_->json();
  if (resume_) j["resume"] = resume_json(*resume_, *loop_);
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
