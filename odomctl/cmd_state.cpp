// odomctl state show: the persisted loop state (issue 17, README "Restarts").
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <memory>

#include <nlohmann/json.hpp>

#include "cmd_state.hpp"
#include "commands.hpp"
#include "odo/firmware/config.hpp"
#include "odo/firmware/state_persist.hpp"

namespace odo::ctl {
namespace {

struct StateOpts {
  std::string path = fw::ResumeSection{}.path;
  bool json = false;
};

std::string hex(const loop::BootId& id) {
  std::string s;
  char b[3];
  for (const std::uint8_t v : id) {
    std::snprintf(b, sizeof b, "%02x", v);
    s += b;
  }
  return s;
}

nlohmann::json state_json(const loop::StateRecord& r) {
  return {{"sequence", r.sequence},
          {"boot_id", hex(r.boot_id)},
          {"stamp", to_seconds(r.stamp)},
          {"left", r.left},
          {"right", r.right},
          {"counter_bits", r.counter_bits},
          {"backend", r.backend},
          {"calibration_state", r.calibration_state},
          {"calibration_sequence", r.calibration_sequence},
          {"metres_per_count_left", r.metres_per_count_left},
          {"metres_per_count_right", r.metres_per_count_right},
          {"wheelbase", r.wheelbase},
          {"x", r.pose.x},
          {"y", r.pose.y},
          {"theta_cumulative", r.pose.theta},
          {"cov", r.cov},
          {"distance", r.distance},
          {"gyro_id", r.gyro_id},
          {"gyro_bias", r.gyro.bias},
          {"gyro_bias_time", r.gyro.bias_time},
          {"gyro_scale", r.gyro.scale},
          {"gyro_scale_valid", r.gyro.scale_valid}};
}

void run_state_show(const StateOpts& o, int& exit_code) {
  auto r = fw::read_state_file(o.path);
  if (!r) {
    std::cerr << "odomctl state show: " << r.error().message << "\n";
    exit_code = kExitFailed;
    return;
  }
  if (o.json) {
    std::cout << state_json(*r).dump() << "\n";
    return;
  }
  std::printf("state record %s: sequence %" PRIu64 ", boot %s\n", o.path.c_str(), r->sequence,
              hex(r->boot_id).c_str());
  std::printf("  sample time %.6f s; counters left %" PRId64 " right %" PRId64
              " (%d bits, backend 0x%02x)\n",
              to_seconds(r->stamp), r->left, r->right, r->counter_bits, r->backend);
  std::printf("  pose x=%.6f m y=%.6f m theta=%.6f rad (cumulative), distance %.3f m\n", r->pose.x,
              r->pose.y, r->pose.theta, r->distance);
  std::printf("  sigma x=%.3g m y=%.3g m theta=%.3g rad\n", std::sqrt(r->cov[0]),
              std::sqrt(r->cov[4]), std::sqrt(r->cov[8]));
  std::printf(
      "  kinematics %.9g / %.9g m per count, wheelbase %.6f m; calibration sequence %" PRIu64 "\n",
      r->metres_per_count_left, r->metres_per_count_right, r->wheelbase, r->calibration_sequence);
  if (r->gyro_id == 0) {
    std::printf("  gyro: none\n");
    return;
  }
  std::printf("  gyro 0x%08" PRIx32 ": bias %.6e rad/s (%.1f s of standstill), scale %.6f (%s)\n",
              r->gyro_id, r->gyro.bias, r->gyro.bias_time, r->gyro.scale,
              r->gyro.scale_valid ? "estimated" : "not estimated");
}

}  // namespace

void add_state(CLI::App& app, int& exit_code) {
  CLI::App* state = app.add_subcommand("state", "the persisted loop state (README \"Restarts\")");
  state->require_subcommand(1);
  auto o = std::make_shared<StateOpts>();
  CLI::App* show = state->add_subcommand("show", "print the newest valid state record");
  show->add_option("--path", o->path, "state file ([resume] path)")->capture_default_str();
  show->add_flag("--json", o->json, "one JSON object");
  show->callback([o, &exit_code] { run_state_show(*o, exit_code); });
}

}  // namespace odo::ctl
