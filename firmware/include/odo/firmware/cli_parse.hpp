// parse_command_line: the CLI11 parse shared by odometryd and odomctl: help and version exit 0
// with CLI11's text, any other parse error prints "<prog>: <what>" on stderr and gives exit 2.
#pragma once

#include <iostream>
#include <optional>

#include <CLI/CLI.hpp>

namespace odo::fw {

// parse_command_line: nullopt to go on, else the process exit code.
inline std::optional<int> parse_command_line(CLI::App& app, int argc, char** argv,
                                             const char* prog) {
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::cerr << prog << ": " << e.what() << "\n";
    return 2;
  }
  return std::nullopt;
}

}  // namespace odo::fw
