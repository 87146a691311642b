// The odometryd application: config -> rig -> loop, status thread, signals, final report.
#pragma once

#include <atomic>
#include <iosfwd>
#include <memory>
#include <string>

namespace odo {
struct KinematicParams;
}
namespace odo::loop {
class OdometryLoop;
}

namespace odo::fw {

struct DaemonOptions {
  std::string config_path;  // empty: the embedded default (simulated LabMate)
  double duration = 0.0;    // [s] of loop time; 0: until SIGINT/SIGTERM (or scenario end + 1 s
                            // with --virtual-time, which cannot be interrupted otherwise)
  bool virtual_time = false;
  bool json = false;                    // one JSON object on stdout at exit
  bool quiet = false;                   // no status lines
  bool stats = false;                   // timing statistics table at exit
  std::string can_log;                  // --can-log: every frame sent, candump -L format
  std::atomic<bool>* reload = nullptr;  // set (e.g. by SIGHUP) to re-read the calibration store
};

struct Config;
struct AppliedCalibration;
class Rig;
class CanLink;
class CalibrationReloader;
class Ros2Output;
struct ResumeWiring;
class SelfCalLink;

// Daemon: odometryd in three steps: configure (config, calibration store, rig, loop, CAN link,
// reloader; start-up report), run (status thread, systemd watchdog, real-time set-up, the loop
// on this thread until stop or duration, clean-stop frames) and report (final lines, --stats,
// --json). configure and run return the process exit code (0: go on).
class Daemon {
 public:
  Daemon(const DaemonOptions& o, std::ostream& out, std::ostream& err);
  ~Daemon();
  int configure();
  int run(std::atomic<bool>& stop);
  void report();

 private:
  int fail(const std::string& message, int code = 2);
  void report_start(const KinematicParams& p);

  const DaemonOptions& o_;
  std::ostream& out_;
  std::ostream& err_;
  std::ostream& log_;  // human-readable progress: stderr when stdout carries JSON
  std::unique_ptr<Config> cfg_;
  std::unique_ptr<AppliedCalibration> cal_;
  std::unique_ptr<Rig> rig_;
  std::unique_ptr<loop::OdometryLoop> loop_;
  std::unique_ptr<CanLink> can_;
  std::unique_ptr<CalibrationReloader> reloader_;
  std::unique_ptr<Ros2Output> ros2_;      // [ros2] enabled; null otherwise
  std::unique_ptr<ResumeWiring> resume_;  // issue 17: persisted state (null in virtual time)
  std::unique_ptr<SelfCalLink> selfcal_;  // [selfcal] enabled
};

// run_daemon: runs the firmware until stop, duration or signal; returns the process exit code.
// `stop` may be set from a signal handler.
int run_daemon(const DaemonOptions& o, std::atomic<bool>& stop, std::ostream& out,
               std::ostream& err);

}  // namespace odo::fw
