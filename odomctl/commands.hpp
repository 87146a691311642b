// odomctl sub-commands: each file registers one command on the CLI11 app.
#pragma once

#include <CLI/CLI.hpp>
#include <fstream>
#include <iostream>
#include <string>

namespace odo::ctl {

// Exit status of odomctl: 0 ok, 1 the operation failed, 2 bad input or bad options.
inline constexpr int kExitOk = 0;
inline constexpr int kExitFailed = 1;
inline constexpr int kExitBadInput = 2;

// write_output_file: writes `text` to `path`; on failure says "odomctl <cmd>: <path>: cannot
// write" on stderr and returns false.
inline bool write_output_file(const std::string& path, const std::string& text, const char* cmd) {
  std::ofstream f(path, std::ios::binary);
  f << text;
  f.close();
  if (!f) {
    std::cerr << "odomctl " << cmd << ": " << path << ": cannot write\n";
    return false;
  }
  return true;
}

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
