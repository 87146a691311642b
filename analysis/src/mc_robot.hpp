// The simulated robot of the error-model Monte Carlos (pose: error_mc.cpp, twist: twist_mc.cpp).
#pragma once

#include "odo/analysis/error_model_tools.hpp"
#include "odo/odometry/kinematics.hpp"
#include "odo/sim/robot.hpp"
#include "odo/sim/sim_run.hpp"

namespace odo::analysis {

// McRobot: the loop's kinematics and the simulated robot's true geometry, equal (no systematic
// error: the runs differ by the injected wheel noise only).
struct McRobot {
  Kinematics believed;
  sim::RobotGeometry truth;
};

// mc_robot: the robot of options o (wheel diameter, wheelbase; 2048 counts, gear ratio 16).
inline Result<McRobot> mc_robot(const McOptions& o) {
  KinematicParams p;
  p.wheel_diameter = o.wheel_diameter;
  p.counts_per_rev = 2048;
  p.gear_ratio = 16;
  p.wheelbase_nominal = p.wheelbase = o.wheelbase;
  auto k = Kinematics::create(p);
  if (!k) return std::move(k).error();
  sim::RobotGeometry g;
  g.wheel_diameter_left = g.wheel_diameter_right = o.wheel_diameter;
  g.wheelbase = o.wheelbase;
  g.counts_per_rev = p.counts_per_rev;
  g.gear_ratio = p.gear_ratio;
  return McRobot{*k, g};
}

// mc_run_options: the loop of options o (rate, error model) with the runs' wheel noise.
inline sim::SimRunOptions mc_run_options(const McOptions& o, sim::TravelPerturbation& noise) {
  sim::SimRunOptions so;
  so.loop.rate_hz = o.rate_hz;
  so.loop.error_model = o.k;
  so.perturbation = &noise;
  return so;
}

}  // namespace odo::analysis
