// SimRun: one simulated drive in virtual time: the simulated robot following a scenario, its
// encoders, a virtual clock and the firmware's own loop. The error-model Monte Carlo, the UMBmark
// simulation and the simulation tests all drive the robot through this one harness.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>

#include "odo/hal/result.hpp"
#include "odo/loop/loop.hpp"
#include "odo/odometry/kinematics.hpp"
#include "odo/sim/robot.hpp"
#include "odo/sim/side_wheels_sim.hpp"
#include "odo/sim/sim_encoder.hpp"
#include "odo/sim/sim_gyro.hpp"
#include "odo/sim/virtual_clock.hpp"

namespace odo::sim {

struct SimRunOptions {
  int counter_bits = 32;                       // simulated counter width, 16..64
  std::int64_t counter_offset = 0;             // counter value at zero counts (start near the wrap)
  loop::LoopConfig loop;                       // rate, error model, calibration status
  TravelPerturbation* perturbation = nullptr;  // floor or wheel noise on the true travel
  SkidSteerBody* skid = nullptr;  // the robot moves as this skid-steer body (not owned)
  // gyro: a simulated gyro of this model fused by the loop (loop.gyrodometry, its noise model
  // taken from the model); the robot first stands still for gyro_lead_in [s] so that the
  // fusion learns the gyro's bias before it moves. Null: odometry alone.
  const GyroModel* gyro = nullptr;
  std::uint64_t gyro_seed = 1;
  double gyro_lead_in = 1.0;
  // side_wheels: several wheels per side of this model, read through a SideCombiner configured
  // by side_config (its read_period the loop's tick), instead of one counter per side. Null:
  // one counter per side (SimEncoderSource).
  const SideWheelsSimParams* side_wheels = nullptr;
  SideWheelsConfig side_config;
};

class SimRun {
 public:
  // create: the robot with true geometry g driving `scenario`, the loop believing `believed`.
  // Errors: the robot's geometry or the loop's configuration is out of range.
  static Result<std::unique_ptr<SimRun>> create(const RobotGeometry& g, const Kinematics& believed,
                                                Scenario scenario, const SimRunOptions& o = {});

  // drive: runs the loop for the scenario plus `extra` [s] of standstill (the last readings see
  // the robot stopped).
  void drive(double extra = 1.0) noexcept;
  // error: true pose minus the loop's pose (x [m], y [m], theta [rad]; cumulative headings).
  Pose2 error() const noexcept;

  SimRobot& robot() noexcept { return robot_; }
  SimEncoderSource& encoder() noexcept { return encoder_; }
  // side_wheels: the several-wheels source (fault injection), null without
  // SimRunOptions::side_wheels.
  SimSideWheelsSource* side_wheels() noexcept { return wheels_ ? &*wheels_ : nullptr; }
  VirtualClock& clock() noexcept { return clock_; }
  // gyro: the simulated gyro (fault injection), null without SimRunOptions::gyro.
  SimGyro* gyro() noexcept { return gyro_ ? &*gyro_ : nullptr; }
  loop::OdometryLoop& loop() noexcept { return *loop_; }
  // loop_config: the loop's configuration (the gyro model's noise and delay filled in): a second
  // loop on the same robot, as after a restart, is created with it.
  const loop::LoopConfig& loop_config() const noexcept { return loop_config_; }

 private:
  SimRun(SimRobot robot, const SimRunOptions& o);
  VirtualClock clock_;
  SimRobot robot_;
  SimEncoderSource encoder_;
  std::optional<SimSideWheelsSource> wheels_;
  std::optional<SimGyro> gyro_;
  loop::LoopConfig loop_config_;
  std::unique_ptr<loop::OdometryLoop> loop_;
};

}  // namespace odo::sim
