#include "odo/sim/sim_run.hpp"

#include <atomic>
#include <utility>

namespace odo::sim {

SimRun::SimRun(SimRobot robot, const SimRunOptions& o)
    : robot_(std::move(robot)), encoder_(robot_, o.counter_bits, o.counter_offset) {}

Result<std::unique_ptr<SimRun>> SimRun::create(const RobotGeometry& g, const Kinematics& believed,
                                               Scenario scenario, const SimRunOptions& o) {
  if (o.gyro != nullptr) scenario.insert(scenario.begin(), Segment{o.gyro_lead_in, 0.0, 0.0});
  auto robot = SimRobot::create(g, std::move(scenario));
  if (!robot) return std::move(robot).error();
  std::unique_ptr<SimRun> run(new SimRun(std::move(robot).value(), o));
  if (o.perturbation != nullptr) run->robot_.set_travel_perturbation(o.perturbation);
  run->robot_.set_skid_body(o.skid);
  loop::LoopConfig lc = o.loop;
  if (o.gyro != nullptr) {
    auto gyro = SimGyro::create(run->robot_, *o.gyro, o.gyro_seed);
    if (!gyro) return std::move(gyro).error();
    run->gyro_.emplace(std::move(gyro).value());
    lc.gyrodometry.noise.rate_noise_density = o.gyro->noise_density;
    // The model's delay as it is (see gyrodometry_params in firmware/src/gyro_backend.cpp).
    lc.gyrodometry.gyro_delay = o.gyro->delay;
  }
  run->loop_config_ = lc;
  if (o.side_wheels != nullptr) {
    auto model = SideWheelsSim::create(*o.side_wheels, g);
    if (!model) return std::move(model).error();
    SideWheelsConfig c = o.side_config;
    c.read_period = 1.0 / lc.rate_hz;
    auto w = SimSideWheelsSource::create(run->robot_, std::move(model).value(), c, o.counter_bits);
    if (!w) return std::move(w).error();
    run->wheels_.emplace(std::move(w).value());
  }
  EncoderSource& enc = run->wheels_ ? static_cast<EncoderSource&>(*run->wheels_) : run->encoder_;
  auto loop = loop::OdometryLoop::create(lc, believed, enc, run->clock_,
                                         run->gyro_ ? &*run->gyro_ : nullptr);
  if (!loop) return std::move(loop).error();
  run->loop_ = std::move(loop).value();
  return run;
}

void SimRun::drive(double extra) noexcept {
  const std::atomic<bool> stop{false};
  loop_->run(from_seconds(scenario_duration(robot_.scenario()) + extra), stop);
}

Pose2 SimRun::error() const noexcept {
  const Pose2& t = robot_.true_pose();
  const Pose2& p = loop_->odometry().pose();
  return Pose2{t.x - p.x, t.y - p.y, t.theta - p.theta};
}

}  // namespace odo::sim
