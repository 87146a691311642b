// Shared set-up for simulation tests: a robot, its encoders, a virtual clock and the loop.
#pragma once

#include <atomic>
#include <memory>

#include "odo/loop/loop.hpp"
#include "odo/sim/robot.hpp"
#include "odo/sim/sim_encoder.hpp"
#include "odo/sim/virtual_clock.hpp"

namespace odo::test {

inline KinematicParams nominal_labmate() {
  return KinematicParams{0.15, 2048, 16, 0.34, 0.34, 1.0, 1.0};
}

// SimRun: owns everything one simulated drive needs; the loop is the firmware's own.
struct SimRun {
  SimRun(const sim::RobotGeometry& g, const Kinematics& believed, sim::Scenario sc, int bits = 32,
         std::int64_t counter_offset = 0, double rate_hz = 100.0)
      : robot(*sim::SimRobot::create(g, std::move(sc))),
        encoder(robot, bits, counter_offset),
        loop(loop::OdometryLoop::create(loop::LoopConfig{rate_hz}, believed, encoder, clock).value()) {}

  // drive: runs the loop for the scenario plus `extra` seconds of standstill.
  void drive(double extra = 1.0) {
    std::atomic<bool> stop{false};
    loop->run(from_seconds(sim::scenario_duration(robot.scenario()) + extra), stop);
  }

  sim::VirtualClock clock;
  sim::SimRobot robot;
  sim::SimEncoderSource encoder;
  std::unique_ptr<loop::OdometryLoop> loop;
};

}  // namespace odo::test
