// odomctl: the command-line tool (replay, calibration, error model, protocol decoding).
#include <iostream>

#include "cmd_state.hpp"
#include "commands.hpp"
#include "odo/firmware/cli_parse.hpp"
#include "odo/firmware/version.hpp"

int main(int argc, char** argv) {
  CLI::App app{"odomctl - tools for the odometry firmware"};
  app.require_subcommand(1);
  app.set_version_flag("--version", std::string("odomctl ") + odo::fw::kVersion);
  int exit_code = odo::ctl::kExitOk;
  odo::ctl::add_replay(app, exit_code);
  odo::ctl::add_calib(app, exit_code);
  odo::ctl::add_errormodel(app, exit_code);
  odo::ctl::add_umbmark(app, exit_code);
  odo::ctl::add_decode(app, exit_code);
  odo::ctl::add_state(app, exit_code);
  odo::ctl::add_selfcal(app, exit_code);
  // Parse errors give kExitBadInput (2), as odometryd.
  if (auto rc = odo::fw::parse_command_line(app, argc, argv, "odomctl")) return *rc;
  return exit_code;
}
