// odometryd: the odometry firmware daemon.
#include <csignal>
#include <iostream>

#include <CLI/CLI.hpp>

#include "odo/firmware/cli_parse.hpp"
#include "odo/firmware/daemon.hpp"
#include "odo/firmware/version.hpp"

#if defined(__SANITIZE_THREAD__)
// ThreadSanitizer builds only: with [ros2] on, the Debian DDS libraries (not instrumented) run
// threads inside odometryd, and TSan, seeing their own synchronisation only partly, reports
// races inside them (as in the ROS 2 test programs, tests/ros2/tsan_suppressions.hpp). Reports
// with a frame in those libraries are suppressed; races between our own stacks still fail.
extern "C" const char* __tsan_default_suppressions() {
  return "called_from_lib:libddsc.so.0debian\n"
         "race:libddsc.so.0debian\n";
}
#endif

namespace {
std::atomic<bool> g_stop{false};
std::atomic<bool> g_reload{false};
extern "C" void on_stop_signal(int) {
  g_stop.store(true);
}
extern "C" void on_reload_signal(int) {
  g_reload.store(true);
}
}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"odometryd - wheel odometry firmware for differential-drive robots"};
  odo::fw::DaemonOptions o;
  app.add_option("--config", o.config_path,
                 "TOML config file (default the built-in simulated robot)")
      ->check(CLI::ExistingFile);
  odo::fw::with_range(
      app.add_option("--duration", o.duration, "loop time to run, then stop [s], 0 = forever"), 0.0,
      1e9)
      ->capture_default_str();
  app.add_flag("--virtual-time", o.virtual_time,
               "run the same loop on a virtual clock as fast as possible (simulation only)");
  app.add_flag("--json", o.json, "print one JSON object with the final state at exit");
  app.add_option("--can-log", o.can_log,
                 "write every CAN frame sent to this file in candump -L format (also with the "
                 "simulated bus)");
  app.add_flag("--quiet", o.quiet, "no status lines");
  app.add_flag("--stats", o.stats,
               "print wake-up latency and compute time statistics (min, mean, p99, p99.9, max) "
               "and missed deadlines at exit");
  app.set_version_flag("--version", std::string("odometryd ") + odo::fw::kVersion);
  if (auto rc = odo::fw::parse_command_line(app, argc, argv, "odometryd")) return *rc;
  struct sigaction sa {};
  sa.sa_handler = on_stop_signal;
  sigemptyset(&sa.sa_mask);
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);
  sa.sa_handler = on_reload_signal;  // SIGHUP: re-read the calibration store
  sigaction(SIGHUP, &sa, nullptr);
  o.reload = &g_reload;
  return odo::fw::run_daemon(o, g_stop, std::cout, std::cerr);
}
