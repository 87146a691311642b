// The encoder hardware of a simulated robot as it appears on a bus, for the daemon's simulated
// backends: two HCTL-1100 register models on a parallel bus, or two ODrive axes on a CAN port,
// both following a SimRobot. The real drivers (drivers/) read them; this side only moves the
// simulated world and puts bytes on the simulated wire.
#pragma once

#include <cstdint>

#include "odo/hal/clock.hpp"
#include "odo/hal/time.hpp"
#include "odo/sim/hctl1100_model.hpp"
#include "odo/sim/robot.hpp"
#include "odo/sim/sim_can_bus.hpp"
#include "odo/sim/sim_odrive.hpp"

namespace odo::sim {

// RobotHctlBus: one HCTL-1100 model per wheel on a SimHctlBus (unit 0 left, unit 1 right);
// before every bus cycle the robot moves on to the loop's time (clock minus epoch) plus the
// cycles already spent in this tick, and the chips follow its wheels. Not movable: the bus
// points at the models and at this hook.
class RobotHctlBus final : public BusCycleHook {
 public:
  // bus_cycle: duration of one register read [ns]; robot, clock: not owned, outlive this.
  RobotHctlBus(Hctl1100Model::Latch latch, TimeNs bus_cycle, SimRobot& robot, Clock& clock,
               TimeNs epoch);
  RobotHctlBus(const RobotHctlBus&) = delete;
  RobotHctlBus& operator=(const RobotHctlBus&) = delete;

  SimHctlBus& bus() noexcept { return bus_; }
  void on_bus_cycle() noexcept override;

 private:
  Hctl1100Model left_, right_;
  SimHctlBus bus_;
  SimRobot& robot_;
  Clock& clock_;
  TimeNs epoch_;
  TimeNs cycle_;
  TimeNs extra_ = 0;  // bus time spent since the clock last changed [ns]
  TimeNs last_now_ = -1;
};

struct RobotOdriveOptions {
  std::uint32_t node_left = 0;  // CAN node ids, 0..63
  std::uint32_t node_right = 1;
  TimeNs period = 0;            // cyclic message period [ns], > 0
  TimeNs stop_left_after = -1;  // the left axis stops sending at this robot time [ns]; -1 never
  TimeNs stop_right_after = -1;
};

// RobotOdriveBus: two simulated ODrive axes publishing the robot's counts on a SimCanPort
// (64 transmit, 1024 receive slots). Not movable: the axes point at the port.
class RobotOdriveBus {
 public:
  // robot: not owned, outlives this; epoch: loop time of robot time 0 [ns].
  RobotOdriveBus(const RobotOdriveOptions& o, SimRobot& robot, TimeNs epoch);
  RobotOdriveBus(const RobotOdriveBus&) = delete;
  RobotOdriveBus& operator=(const RobotOdriveBus&) = delete;

  SimCanPort& port() noexcept { return port_; }
  // publish_until: every cyclic message due up to loop time `now` [ns] is put on the port (the
  // robot moved to each message's time), then the robot moves on to `now` (the truth at the
  // loop's time).
  void publish_until(TimeNs now) noexcept;

 private:
  bool sends(TimeNs stop_after) const noexcept { return stop_after < 0 || next_ < stop_after; }
  SimCanPort port_;
  SimOdrive odrive_;
  SimRobot& robot_;
  TimeNs epoch_;
  RobotOdriveOptions opts_;
  TimeNs next_ = 0;  // robot time of the next cyclic message [ns]
};

}  // namespace odo::sim
