// odomctl state: the persisted loop state (issue 17, README "Restarts").
#pragma once

#include <CLI/CLI.hpp>

namespace odo::ctl {

// add_state: `odomctl state show` (the newest valid state record).
void add_state(CLI::App& app, int& exit_code);

}  // namespace odo::ctl
