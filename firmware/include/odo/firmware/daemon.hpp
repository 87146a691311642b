// The odometryd application: config -> rig -> loop, status thread, signals, final report.
#pragma once

#include <atomic>
#include <iosfwd>
#include <string>

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

// run_daemon: runs the firmware until stop, duration or signal; returns the process exit code.
// `stop` may be set from a signal handler.
int run_daemon(const DaemonOptions& o, std::atomic<bool>& stop, std::ostream& out,
               std::ostream& err);

}  // namespace odo::fw
