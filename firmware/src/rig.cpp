#include "odo/firmware/rig.hpp"

#include <sstream>

#include "encoder_backends.hpp"
#include "gyro_backend.hpp"
#include "odo/drivers/monotonic_clock.hpp"
#include "odo/sim/robot.hpp"
#include "odo/sim/side_wheels_sim.hpp"
#include "odo/sim/sim_encoder.hpp"
#include "odo/sim/truth.hpp"
#include "odo/sim/virtual_clock.hpp"

namespace odo::fw {

namespace {

// make_scenario: the [sim] section's squares (sim_hal composes them: the microcontroller
// firmware's simulated run drives the same path), after the simulated gyro's standstill.
sim::Scenario make_scenario(const Config& cfg, const Kinematics& k) {
  const SimSection& s = cfg.sim;
  sim::SquareOptions o;
  o.side = s.side;
  o.speed = s.speed;
  o.turn_rate = s.turn_rate;
  o.pause = s.pause;
  const sim::SquareSet set = s.scenario == SimScenario::kSquares     ? sim::SquareSet::kBoth
                             : s.scenario == SimScenario::kSquareCcw ? sim::SquareSet::kCcw
                             : s.scenario == SimScenario::kSquareCw  ? sim::SquareSet::kCw
                                                                     : sim::SquareSet::kNone;
  sim::Scenario sc = sim::squares_scenario(k, o, set);
  if (s.start_delay > 0.0) sc.insert(sc.begin(), {s.start_delay, 0.0, 0.0});
  // With a gyro the robot first stands still, as a real one does after power-up, so that the
  // fusion learns the gyro's bias before the first move (detection is off until then): still_time
  // to confirm the standstill, still_time of averaging, and 0.25 s for real-time ticks (with
  // exactly 2 still_time the averaging ended within a tick of still_time, valid or not by chance).
  if (simulated_gyro(cfg)) sc.insert(sc.begin(), {2.0 * cfg.gyro.still_time + 0.25, 0.0, 0.0});
  return sc;
}

}  // namespace

struct Rig::Impl {
  std::unique_ptr<Clock> clock;
  std::unique_ptr<sim::SimRobot> robot;
  std::unique_ptr<EncoderSource> sim_encoder;  // SimEncoderSource or SimSideWheelsSource
  std::unique_ptr<EncoderSource> encoder_wrapper;
  EncoderSource* encoder = nullptr;
  std::unique_ptr<sim::TruthRecorder> truth;
  std::unique_ptr<EncoderBackend> backend;  // hctl1100 / gpio (encoder_backends.hpp)
  std::string description;
  double scenario_duration = 0.0;
  std::unique_ptr<GyroWiring> gyro;  // [gyro]; null: none
  GyrodometryParams gyro_params;     // from [gyro] (and [can_gyro]'s bus)
  TimeNs sim_epoch = 0;  // real-time simulation: the robot's time zero of the fixed-epoch backends
};

Rig::Rig(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
Rig::~Rig() = default;
Rig::Rig(Rig&&) noexcept = default;
Rig& Rig::operator=(Rig&&) noexcept = default;

Clock& Rig::clock() noexcept {
  return *impl_->clock;
}
EncoderSource& Rig::encoder() noexcept {
  return *impl_->encoder;
}
sim::TruthRecorder* Rig::truth() noexcept {
  return impl_->truth.get();
}
const std::string& Rig::describe() const noexcept {
  return impl_->description;
}
double Rig::scenario_duration() const noexcept {
  return impl_->scenario_duration;
}
YawRateSource* Rig::gyro() noexcept {
  return impl_->gyro ? &impl_->gyro->gyro() : nullptr;
}
GyrodometryParams Rig::gyrodometry() const {
  return impl_->gyro_params;
}

// add_gyro: [gyro] on top of the wired encoders: the IIO device, or the simulated gyro on the
// simulated robot (on its clock: virtual, the EpochEncoder's epoch, or the backends' fixed one).
Status Rig::add_gyro(const Config& cfg, Impl& impl, bool virtual_time) {
  impl.gyro_params = gyrodometry_params(cfg);
  const GyroBackend be = cfg.gyro.backend;
  if (be == GyroBackend::kNone) return Ok{};
  const bool simulated = simulated_gyro(cfg);
  // parse_config refuses this pairing at its line (check_gyro_robot); a Config built in code
  // reaches here.
  if (simulated && impl.robot == nullptr)
    return make_error(Errc::kInvalidArgument,
                      cfg.source + ": gyro.backend = \"" + std::string(name_of(be)) + "\"" +
                          (be == GyroBackend::kCan ? " with can_gyro.bus = \"sim\"" : "") +
                          " needs a simulated robot (encoder backend sim, or "
                          "hctl1100/can_encoder with bus = \"sim\")");
  const TimeNs* epoch = nullptr;
  if (simulated && !virtual_time) {
    auto* e = dynamic_cast<sim::EpochEncoder*>(impl.encoder_wrapper.get());
    epoch = impl.backend ? &impl.sim_epoch : &e->epoch();
  }
  auto g = be == GyroBackend::kIio   ? make_iio_gyro(cfg)
           : be == GyroBackend::kSim ? make_sim_gyro(cfg, *impl.robot, epoch)
           : simulated               ? make_can_sim_gyro(cfg, *impl.robot, epoch)
                                     : make_can_socketcan_gyro(cfg);
  if (!g) return std::move(g).error();
  impl.gyro = std::move(g).value();
  impl.description += ", " + impl.gyro->describe();
  return Ok{};
}

namespace {

// sim_encoder: the simulated robot's counters: one per side (SimEncoderSource) or, with
// encoder.wheels_per_side > 1, that many wheels per side combined (SimSideWheelsSource, the
// wheel model's documented defaults).
Result<std::unique_ptr<EncoderSource>> sim_encoder(const Config& cfg, sim::SimRobot& robot) {
  const SideWheelsConfig& w = cfg.encoder.side;
  if (w.wheels_per_side == 1)
    return std::unique_ptr<EncoderSource>(
        std::make_unique<sim::SimEncoderSource>(robot, cfg.sim.counter_bits));
  sim::SideWheelsSimParams p;
  p.wheels_per_side = w.wheels_per_side;
  auto model = sim::SideWheelsSim::create(p, robot.geometry());
  if (!model) return std::move(model).error();
  auto src =
      sim::SimSideWheelsSource::create(robot, std::move(model).value(), w, cfg.sim.counter_bits);
  if (!src) return std::move(src).error();
  return std::unique_ptr<EncoderSource>(
      std::make_unique<sim::SimSideWheelsSource>(std::move(src).value()));
}

// wheels_text: "N wheels per side (combine), " with several; "" with one (as before).
std::string wheels_text(const SideWheelsConfig& w) {
  if (w.wheels_per_side == 1) return {};
  return std::to_string(w.wheels_per_side) + " wheels per side (" +
         std::string(choice_name(kSideCombineNames, w.combine)) + "), ";
}

// hardware_backend: the real encoder backend named in the config (not simulated; a virtual
// clock is refused).
Result<std::unique_ptr<EncoderBackend>> hardware_backend(const Config& cfg, const Kinematics& k,
                                                         bool virtual_time) {
  const EncoderKind be = cfg.encoder.backend;
  if (virtual_time)
    return make_error(Errc::kInvalidArgument,
                      "--virtual-time needs a simulated encoder "
                      "backend (encoder.backend = \"" +
                          std::string(name_of(be)) + "\")");
  return be == EncoderKind::kGpio       ? make_gpio_backend(cfg)
         : be == EncoderKind::kHctl1100 ? make_hctl_gpio_backend(cfg, k)
         : be == EncoderKind::kSerial   ? make_serial_tty_backend(cfg, k)
                                        : make_can_socketcan_backend(cfg, k);
}

}  // namespace

Result<Rig> Rig::create(const Config& cfg, const Kinematics& k, bool virtual_time) {
  auto impl = std::make_unique<Impl>();
  if (!simulated_robot(cfg)) {
    auto b = hardware_backend(cfg, k, virtual_time);
    if (!b) return std::move(b).error();
    impl->backend = std::move(b).value();
    impl->clock = std::make_unique<drivers::MonotonicClock>();
    impl->encoder = &impl->backend->encoder();
    impl->description = impl->backend->describe() + ", real time (CLOCK_MONOTONIC)";
    if (auto st = add_gyro(cfg, *impl, virtual_time); !st) return std::move(st).error();
    return Rig(std::move(impl));
  }
  // The simulated robot, read directly (backend sim) or through a model of the counter chip or
  // of the CAN motor controllers on their simulated bus.
  const bool modelled = cfg.encoder.backend != EncoderKind::kSim;
  const sim::RobotGeometry g =
      sim::simulated_geometry(cfg.sim.robot == SimRobotKind::kLabmate, k.params());
  sim::Scenario scenario = make_scenario(cfg, k);
  impl->scenario_duration = sim::scenario_duration(scenario);
  auto robot = sim::SimRobot::create(g, std::move(scenario));
  if (!robot) return std::move(robot).error();
  impl->robot = std::make_unique<sim::SimRobot>(std::move(robot).value());
  auto enc = sim_encoder(cfg, *impl->robot);
  if (!enc) return std::move(enc).error();
  impl->sim_encoder = std::move(enc).value();
  if (virtual_time) {
    impl->clock = std::make_unique<sim::VirtualClock>();
    impl->encoder = impl->sim_encoder.get();
  } else {
    impl->clock = std::make_unique<drivers::MonotonicClock>();
    impl->encoder_wrapper = std::make_unique<sim::EpochEncoder>(*impl->sim_encoder);
    impl->encoder = impl->encoder_wrapper.get();
  }
  if (modelled) {
    const TimeNs epoch = virtual_time ? 0 : impl->clock->now();
    impl->sim_epoch = epoch;
    const EncoderKind be = cfg.encoder.backend;
    auto b = be == EncoderKind::kHctl1100
                 ? make_hctl_sim_backend(cfg, k, *impl->robot, *impl->clock, epoch)
             : be == EncoderKind::kSerial ? make_serial_sim_backend(cfg, k, *impl->robot, epoch)
                                          : make_can_sim_backend(cfg, k, *impl->robot, epoch);
    if (!b) return std::move(b).error();
    impl->backend = std::move(b).value();
    impl->encoder = &impl->backend->encoder();
  }
  impl->truth = std::make_unique<sim::TruthRecorder>(*impl->robot);
  std::ostringstream d;
  d << "simulated robot '" << name_of(cfg.sim.robot) << "' (true wheelbase " << g.wheelbase * 1e3
    << " mm, D_R/D_L " << g.wheel_diameter_right / g.wheel_diameter_left << "), scenario '"
    << name_of(cfg.sim.scenario) << "' (" << impl->scenario_duration << " s), "
    << cfg.sim.counter_bits << "-bit counters, " << wheels_text(cfg.encoder.side)
    << (modelled ? impl->backend->describe() + ", " : std::string())
    << (virtual_time ? "virtual time" : "real time (CLOCK_MONOTONIC)");
  impl->description = d.str();
  if (auto st = add_gyro(cfg, *impl, virtual_time); !st) return std::move(st).error();
  return Rig(std::move(impl));
}

}  // namespace odo::fw
