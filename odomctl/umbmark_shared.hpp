// What the UMBmark sub-commands share (cmd_umbmark.cpp, cmd_umbmark_record.cpp).
#pragma once

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>
#include <ostream>
#include <string>

#include "odo/calibration/record.hpp"
#include "odo/calibration/umbmark.hpp"
#include "odo/hal/angle.hpp"

namespace odo::ctl {

// compute_json: the documented keys of `umbmark compute --json` (SI units, radians); also what
// `odomctl calib import` reads (c_l, c_r, b_new, e_max_syst, n_cw, n_ccw).
nlohmann::json compute_json(const calib::UmbmarkResult& r);

// print_compute: the report of `umbmark compute` in mm and degrees; `wheelbase` [m] the robot
// used during the runs.
void print_compute(std::ostream& out, const calib::UmbmarkResult& r, double wheelbase);

// save_factors: stores `rec` (time stamped now) in the calibration store at `path`; messages
// start "odomctl <cmd>: " and name the path once.
bool save_factors(const std::string& path, calib::CalibrationRecord rec, const char* cmd);

// add_record: `odomctl umbmark record` (the guided session on a real robot).
void add_record(CLI::App& umbmark, int& exit_code);

}  // namespace odo::ctl
