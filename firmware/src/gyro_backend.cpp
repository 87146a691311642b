#include "gyro_backend.hpp"

#include <cmath>
#include <sstream>

#include "odo/drivers/iio_gyro.hpp"
#include "odo/sim/sim_gyro.hpp"
#include "odo/sim/truth.hpp"

namespace odo::fw {
namespace {

sim::GyroModel sim_model(const GyroSection& g) {
  return g.model == GyroModelKind::kIndustrial ? sim::industrial_gyro() : sim::consumer_gyro();
}

// or_model: the configured value, or the model's when the key was not set.
double or_model(double configured, double model) {
  return configured == GyroSection::kNotSet ? model : configured;
}

class IioBackend final : public GyroWiring {
 public:
  IioBackend(std::unique_ptr<drivers::IioGyro> g, std::string d)
      : gyro_(std::move(g)), describe_(std::move(d)) {}
  YawRateSource& gyro() noexcept override { return *gyro_; }
  const std::string& describe() const noexcept override { return describe_; }

 private:
  std::unique_ptr<drivers::IioGyro> gyro_;
  std::string describe_;
};

class SimBackend final : public GyroWiring {
 public:
  SimBackend(sim::SimGyro g, const TimeNs* epoch, std::string d)
      : sim_(std::move(g)), describe_(std::move(d)) {
    if (epoch != nullptr) epoch_gyro_ = std::make_unique<sim::EpochGyro>(sim_, *epoch);
  }
  YawRateSource& gyro() noexcept override {
    return epoch_gyro_ ? static_cast<YawRateSource&>(*epoch_gyro_) : sim_;
  }
  const std::string& describe() const noexcept override { return describe_; }

 private:
  sim::SimGyro sim_;
  std::unique_ptr<sim::EpochGyro> epoch_gyro_;
  std::string describe_;
};

}  // namespace

GyrodometryParams gyrodometry_params(const GyroSection& g) {
  GyrodometryParams p;
  if (g.backend == GyroBackend::kSim) {
    const sim::GyroModel m = sim_model(g);
    // The model's bias random walk K moves the bias by K sqrt(100 s) in 100 s: its instability
    // as the data sheet states it (sim_gyro.hpp). Its delay as it is: a sample covers the period
    // before its time and is available `delay` later, and a tick's rate is the mean of the
    // samples that became available in it, so the mean lags the tick by `delay` (on average;
    // exactly when the samples are aligned with the ticks, as in the simulator).
    p.noise.rate_noise_density = m.noise_density;
    p.noise.bias_instability = m.bias_walk * 10.0;
    p.gyro_delay = m.delay;
  }
  p.noise.rate_noise_density = or_model(g.noise_density, p.noise.rate_noise_density);
  p.noise.bias_instability = or_model(g.bias_instability, p.noise.bias_instability);
  p.noise.scale_tolerance = or_model(g.scale_tolerance, p.noise.scale_tolerance);
  p.gyro_delay = or_model(g.delay, p.gyro_delay);
  p.delay_tolerance = g.delay_tolerance;
  p.window = g.window;
  p.k_sigma = g.k_sigma;
  p.max_wheel_speed = g.max_wheel_speed;
  p.max_wheel_accel = g.max_wheel_accel;
  p.still_time = g.still_time;
  p.bias_tau = g.bias_tau;
  return p;
}

Result<std::unique_ptr<GyroWiring>> make_iio_gyro(const Config& cfg) {
  const GyroSection& g = cfg.gyro;
  drivers::IioGyroConfig c;
  c.device = g.device;
  c.axis = g.axis == GyroAxis::kX   ? drivers::IioAxis::kX
           : g.axis == GyroAxis::kY ? drivers::IioAxis::kY
                                    : drivers::IioAxis::kZ;
  c.sign = g.sign;
  c.mode = g.mode == GyroMode::kPolled ? drivers::IioMode::kPolled : drivers::IioMode::kBuffered;
  c.expected_rate = g.rate;
  c.trigger = g.trigger;
  c.buffer_length = g.buffer_length;
  c.stale_timeout = static_cast<TimeNs>(std::llround(g.stale_timeout * 1e9));
  auto opened = drivers::IioGyro::open(c);
  if (!opened) {
    return make_error(opened.error().code,
                      cfg.source + ": [gyro] backend = \"iio\": " + opened.error().message);
  }
  std::ostringstream d;
  d << "IIO gyro '" << (*opened)->name() << "' (" << (*opened)->device_dir() << ", in_anglvel_"
    << drivers::axis_letter(c.axis) << ", sign " << g.sign << ", " << name_of(g.mode) << ")";
  return std::unique_ptr<GyroWiring>(
      std::make_unique<IioBackend>(std::move(opened).value(), d.str()));
}

Result<std::unique_ptr<GyroWiring>> make_sim_gyro(const Config& cfg, sim::SimRobot& robot,
                                                  const TimeNs* epoch) {
  const GyroSection& g = cfg.gyro;
  const auto stale = static_cast<TimeNs>(std::llround(g.stale_timeout * 1e9));
  auto made = sim::SimGyro::create(robot, sim_model(g), static_cast<std::uint64_t>(g.seed), stale);
  if (!made) return std::move(made).error();
  std::ostringstream d;
  d << "simulated " << name_of(g.model) << " gyro (seed " << g.seed << ")";
  return std::unique_ptr<GyroWiring>(
      std::make_unique<SimBackend>(std::move(made).value(), epoch, d.str()));
}

}  // namespace odo::fw
