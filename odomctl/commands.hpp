// odomctl sub-commands: each file registers one command on the CLI11 app.
#pragma once

#include <CLI/CLI.hpp>
#include <initializer_list>
#include <iostream>
#include <string>

#include "odo/hal/result.hpp"
#include "odo/odometry/gyrodometry.hpp"
#include "odo/odometry/kinematics.hpp"

namespace odo::ctl {

// Exit status of odomctl: 0 ok, 1 the operation failed, 2 bad input or bad options.
inline constexpr int kExitOk = 0;
inline constexpr int kExitFailed = 1;
inline constexpr int kExitBadInput = 2;

// write_output_file: writes `text` to a temporary file beside `path` and renames it over
// `path` (never half-written); on failure says "odomctl <cmd>: <path>: cannot write: <reason>"
// on stderr and returns false.
bool write_output_file(const std::string& path, const std::string& text, const char* cmd);

// output_path_problem: why `path` cannot be created or written (empty when it can), checked
// before any work starts: "<path>: cannot create: No such file or directory".
std::string output_path_problem(const std::string& path);
// output_paths_ok: output_path_problem() of each non-empty path; the first problem is printed
// as "odomctl <cmd>: <problem>" and false returned.
bool output_paths_ok(std::initializer_list<std::string> paths, const char* cmd);

// ProgressLine: on a terminal (stderr is a tty) one line "  <what> done/total, N s left" that
// updates in place; off a terminal nothing until finish(), which prints nothing either (the
// command's own summary says what was done).
class ProgressLine {
 public:
  explicit ProgressLine(std::string what);
  // update: done of total items finished [-].
  void update(int done, int total);
  // finish: ends the updating line (a newline on a terminal).
  void finish();

 private:
  std::string what_;
  bool tty_;
  double start_;  // [s] monotonic
  bool shown_ = false;
};

// take_choice: stores a command-line choice parsed from its text (the only place the text is
// read) in `out`; on failure says "odomctl <cmd>: <error>" on stderr, sets kExitBadInput and
// returns false.
template <class E>
bool take_choice(Result<E> parsed, E& out, const char* cmd, int& exit_code) {
  if (parsed) {
    out = *parsed;
    return true;
  }
  std::cerr << "odomctl " << cmd << ": " << parsed.error().message << "\n";
  exit_code = kExitBadInput;
  return false;
}

// KinematicsOpts: the robot's kinematics as the log commands take them (replay, calib
// fit-fixes): nominal geometry, the factors in use and the counter width.
struct KinematicsOpts {
  double wheel_diameter = 0, counts_per_rev = 0, gear_ratio = 1, wheelbase = 0;  // m, -, -, m
  double cl = 1, cr = 1;
  int bits = 64;
  // --config: odometryd's config file, read through the daemon's own reader and tables: its
  // [robot] with the calibration store it names applied, [error_model] and [gyro] (instead of
  // the geometry options, which it excludes).
  std::string config;
};

// KinematicsHelp: the wording of --wheelbase, --cl and --cr, which differs by command.
struct KinematicsHelp {
  const char* wheelbase;
  const char* cl;
  const char* cr;
};

// add_kinematics_options: --wheel-diameter, --counts-per-rev, --gear-ratio, --wheelbase, --cl,
// --cr and --counter-bits on `c`, stored in `k` (which must outlive the parse).
void add_kinematics_options(CLI::App& c, KinematicsOpts& k, const KinematicsHelp& help);

// make_kinematics: the Kinematics of `k` (of its --config when given); the error names the
// field and its range, or the config file's line.
Result<Kinematics> make_kinematics(const KinematicsOpts& k);

// LogRun: what a log command runs the loop's code with: the kinematics, and the gyrodometry
// parameters odometryd would run with (its config's [gyro] and [error_model] with --config,
// else the fusion's defaults; tick and heading_quantum are set by the caller, as the loop sets
// them from its rate and kinematics).
struct LogRun {
  Kinematics kinematics;
  GyrodometryParams fusion;
};
// log_run: the LogRun of `k`, reading --config once; errors as make_kinematics.
Result<LogRun> log_run(const KinematicsOpts& k);

// add_replay: `odomctl replay` (integrate a log of raw counts).
void add_replay(CLI::App& app, int& exit_code);
// add_calib: `odomctl calib show|set|import|export|reset` (the calibration store).
void add_calib(CLI::App& app, int& exit_code);
// add_calib_fit_fixes: `odomctl calib fit-fixes` (self-calibration from absolute fixes).
void add_calib_fit_fixes(CLI::App& calib, int& exit_code);
// add_selfcal: `odomctl selfcal simulate` (self-calibration on the simulated LabMate).
void add_selfcal(CLI::App& app, int& exit_code);
// add_errormodel: `odomctl errormodel validate|fit` (Chong-Kleeman error model).
void add_errormodel(CLI::App& app, int& exit_code);
// add_umbmark: `odomctl umbmark compute|scale|simulate` (UMBmark calibration).
void add_umbmark(CLI::App& app, int& exit_code);

// add_decode: `odomctl decode FILE [--csv]` (candump -L log of the CAN pose protocol).
void add_decode(CLI::App& app, int& exit_code);

}  // namespace odo::ctl
