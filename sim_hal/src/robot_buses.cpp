#include "odo/sim/robot_buses.hpp"

namespace odo::sim {

RobotHctlBus::RobotHctlBus(Hctl1100Model::Latch latch, TimeNs bus_cycle, SimRobot& robot,
                           Clock& clock, TimeNs epoch)
    : left_(latch),
      right_(latch),
      bus_(&left_, &right_),
      robot_(robot),
      clock_(clock),
      epoch_(epoch),
      cycle_(bus_cycle) {
  bus_.set_hook(this);
}

void RobotHctlBus::on_bus_cycle() noexcept {
  // Bus cycles take time: the wheels move on while the driver reads byte by byte (counted
  // from the tick's clock reading, so the model never runs ahead of the simulation).
  const TimeNs now = clock_.now();
  if (now != last_now_) {
    last_now_ = now;
    extra_ = 0;
  }
  extra_ += cycle_;
  const TimeNs t = now - epoch_ + extra_;
  if (t > robot_.time()) robot_.advance_to(t);
  left_.follow(robot_.counts_left());
  right_.follow(robot_.counts_right());
}

RobotOdriveBus::RobotOdriveBus(const RobotOdriveOptions& o, SimRobot& robot, TimeNs epoch)
    : port_(64, 1024),
      odrive_(port_, SimOdriveOptions{o.node_left, o.node_right, 8192}),
      robot_(robot),
      epoch_(epoch),
      opts_(o) {}

void RobotOdriveBus::publish_until(TimeNs now) noexcept {
  const TimeNs t = now - epoch_;
  for (; next_ <= t; next_ += opts_.period) {
    if (next_ > robot_.time()) robot_.advance_to(next_);
    odrive_.set_sending(0, sends(opts_.stop_left_after));
    odrive_.set_sending(1, sends(opts_.stop_right_after));
    odrive_.publish(next_ + epoch_, robot_.counts_left(), robot_.counts_right());
  }
  if (t > robot_.time()) robot_.advance_to(t);
}

}  // namespace odo::sim
