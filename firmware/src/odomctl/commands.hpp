// odomctl sub-commands: each file registers one command on the CLI11 app.
#pragma once

#include <CLI/CLI.hpp>

namespace odo::ctl {

// Exit status of odomctl: 0 ok, 1 the operation failed, 2 bad input or bad options.
inline constexpr int kExitOk = 0;
inline constexpr int kExitFailed = 1;
inline constexpr int kExitBadInput = 2;

// add_replay: `odomctl replay` (integrate a log of raw counts).
void add_replay(CLI::App& app, int& exit_code);
// add_calib: `odomctl calib show|set|import|export|reset` (the calibration store).
void add_calib(CLI::App& app, int& exit_code);
// add_errormodel: `odomctl errormodel validate|fit` (Chong-Kleeman error model).
void add_errormodel(CLI::App& app, int& exit_code);

// add_decode: `odomctl decode FILE [--csv]` (candump -L log of the CAN pose protocol).
void add_decode(CLI::App& app, int& exit_code);

}  // namespace odo::ctl
