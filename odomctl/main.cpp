// odomctl: the command-line tool (replay, calibration, error model, protocol decoding).
#include <iostream>

#include "commands.hpp"
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
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::cerr << "odomctl: " << e.what() << "\n";
    return odo::ctl::kExitBadInput;
  }
  return exit_code;
}
