#include <fstream>
#include <iostream>

#include <nlohmann/json.hpp>

#include "commands.hpp"
#include "odo/analysis/replay.hpp"
#include "odo/hal/angle.hpp"

namespace odo::ctl {

namespace {

struct ReplayOpts {
  std::string ticks;
  KinematicsOpts kin;
  bool json = false;
  bool no_gyro = false;  // ignore a gyro_z column
};

// gyro_json: the fusion's counters of a replay with a gyro_z column.
nlohmann::json gyro_json(const FusionCounters& c) {
  return {{"disagreements", c.disagreements},
          {"speed_events", c.speed_events},
          {"accel_events", c.accel_events},
          {"gyro_used_ticks", c.gyro_used_ticks}};
}

// run_replay: `odomctl ... replay` once its options are parsed; sets exit_code.
void run_replay(const ReplayOpts& o, int& exit_code) {
  auto run = log_run(o.kin);
  if (!run) {
    std::cerr << "odomctl replay: " << run.error().message << "\n";
    exit_code = kExitBadInput;
    return;
  }
  std::ifstream in(o.ticks, std::ios::binary);
  if (!in) {
    std::cerr << "odomctl replay: " << o.ticks << ": cannot open\n";
    exit_code = kExitBadInput;
    return;
  }
  analysis::ReplayGyro gyro;
  gyro.use = !o.no_gyro;
  gyro.params = run->fusion;
  auto r = analysis::replay_ticks(in, o.ticks, run->kinematics, o.kin.bits, gyro);
  if (!r) {
    std::cerr << "odomctl replay: " << r.error().message << "\n";
    exit_code = kExitBadInput;
    return;
  }
  if (o.json) {
    nlohmann::json j{{"x", r->pose.x},
                     {"y", r->pose.y},
                     {"theta", r->pose.theta},
                     {"distance", r->distance},
                     {"samples", r->samples}};
    if (r->fused) j["gyro"] = gyro_json(r->fusion);
    std::cout << j.dump() << "\n";
  } else {
    std::cout << "samples   " << r->samples << "\n"
              << "x         " << r->pose.x << " m\n"
              << "y         " << r->pose.y << " m\n"
              << "theta     " << r->pose.theta << " rad (cumulative, " << r->pose.theta * kDegPerRad
              << " deg)\n"
              << "distance  " << r->distance << " m\n";
    if (r->fused)
      std::cout << "gyro      fused: " << r->fusion.disagreements << " disagreements, "
                << r->fusion.speed_events + r->fusion.accel_events << " limit events, "
                << r->fusion.gyro_used_ticks << " gyro-heading ticks\n";
  }
  exit_code = kExitOk;
}

}  // namespace

void add_replay(CLI::App& app, int& exit_code) {
  auto o = std::make_shared<ReplayOpts>();
  CLI::App* c = app.add_subcommand("replay", "integrate a CSV log of raw counter readings");
  c->add_option("--ticks", o->ticks,
                "CSV file with header t,left,right[,gyro_z] (gyro_z [rad/s]: fused)")
      ->required();
  add_kinematics_options(*c, o->kin,
                         {"effective wheelbase b [m]", "left wheel correction factor c_L",
                          "right wheel correction factor c_R"});
  c->add_flag("--json", o->json, "print one JSON object");
  c->add_flag("--no-gyro", o->no_gyro, "ignore the gyro_z column (odometry alone)");
  c->callback([o, &exit_code] { run_replay(*o, exit_code); });
}

}  // namespace odo::ctl
