// Shared set-up for simulation tests: sim_hal's simulated-run harness (robot, encoders, virtual
// clock, the firmware's own loop) under the names the tests use.
#pragma once

#include <atomic>
#include <memory>

#include "odo/loop/loop.hpp"
#include "odo/sim/robot.hpp"
#include "odo/sim/sim_encoder.hpp"
#include "odo/sim/sim_run.hpp"
#include "odo/sim/virtual_clock.hpp"

namespace odo::test {

inline KinematicParams nominal_labmate() {
  return KinematicParams{0.15, 2048, 16, 0.34, 0.34, 1.0, 1.0};
}

inline std::unique_ptr<sim::SimRun> make_sim_run(const sim::RobotGeometry& g,
                                                 const Kinematics& believed, sim::Scenario sc,
                                                 int bits, std::int64_t counter_offset,
                                                 double rate_hz) {
  sim::SimRunOptions o;
  o.counter_bits = bits;
  o.counter_offset = counter_offset;
  o.loop.rate_hz = rate_hz;
  return sim::SimRun::create(g, believed, std::move(sc), o).value();
}

// SimRun: owns everything one simulated drive needs; the loop is the firmware's own.
struct SimRun {
  SimRun(const sim::RobotGeometry& g, const Kinematics& believed, sim::Scenario sc, int bits = 32,
         std::int64_t counter_offset = 0, double rate_hz = 100.0)
      : run(make_sim_run(g, believed, std::move(sc), bits, counter_offset, rate_hz)),
        clock(run->clock()),
        robot(run->robot()),
        encoder(run->encoder()),
        loop(&run->loop()) {}

  // drive: runs the loop for the scenario plus `extra` seconds of standstill.
  void drive(double extra = 1.0) { run->drive(extra); }

  std::unique_ptr<sim::SimRun> run;
  sim::VirtualClock& clock;
  sim::SimRobot& robot;
  sim::SimEncoderSource& encoder;
  loop::OdometryLoop* loop;
};

}  // namespace odo::test
