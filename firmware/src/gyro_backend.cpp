#include "gyro_backend.hpp"

#include <optional>
#include <sstream>

#include "odo/drivers/can_gyro.hpp"
#include "odo/drivers/iio_gyro.hpp"
#include "odo/drivers/socketcan_bus.hpp"
#include "odo/sim/sim_can_imu.hpp"
#include "odo/sim/sim_gyro.hpp"
#include "odo/sim/truth.hpp"

namespace odo::fw {
namespace {

sim::GyroModel sim_model(const GyroSection& g) {
  return g.model == GyroModelKind::kIndustrial ? sim::industrial_gyro() : sim::consumer_gyro();
}

// model_gyro: the simulated gyro of [gyro] model and seed on `robot`.
Result<sim::SimGyro> model_gyro(const GyroSection& g, sim::SimRobot& robot) {
  return sim::SimGyro::create(robot, sim_model(g), static_cast<std::uint64_t>(g.seed),
                              from_seconds(g.stale_timeout));
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

// CanSocketBackend: a CAN IMU on a SocketCAN interface; the source reads the socket.
class CanSocketBackend final : public GyroWiring {
 public:
  CanSocketBackend(std::unique_ptr<drivers::SocketCanBus> bus, std::string d)
      : bus_(std::move(bus)), describe_(std::move(d)) {}
  void set_source(drivers::CanGyroSource g) { gyro_.emplace(std::move(g)); }
  drivers::SocketCanBus& bus() noexcept { return *bus_; }
  YawRateSource& gyro() noexcept override { return *gyro_; }
  const std::string& describe() const noexcept override { return describe_; }

 private:
  std::unique_ptr<drivers::SocketCanBus> bus_;  // the source points at it
  std::optional<drivers::CanGyroSource> gyro_;
  std::string describe_;
};

// CanSimBackend: the simulated CAN IMU on the simulated robot; before each read it sends every
// sample due (on the robot's clock), then the real decoder reads its port.
class CanSimBackend final : public GyroWiring, public YawRateSource {
 public:
  CanSimBackend(sim::SimGyro g, sim::SimRobot& robot, const sim::SimCanImuOptions& o,
                const TimeNs* epoch, std::string d)
      : imu_(std::move(g), robot, o), describe_(std::move(d)) {
    if (epoch != nullptr) epoch_gyro_ = std::make_unique<sim::EpochGyro>(*this, *epoch);
  }
  void set_source(drivers::CanGyroSource g) { source_.emplace(std::move(g)); }
  sim::SimCanPort& port() noexcept { return imu_.port(); }
  YawRateSource& gyro() noexcept override {
    return epoch_gyro_ ? static_cast<YawRateSource&>(*epoch_gyro_) : *this;
  }
  const std::string& describe() const noexcept override { return describe_; }
  GyroSample read(TimeNs now) noexcept override {
    GyroSample s;
    read_into(now, s);
    return s;
  }
  void read_into(TimeNs now, GyroSample& out) noexcept override {
    imu_.publish_until(now);
    source_->read_into(now, out);
  }
  double full_scale() const noexcept override { return source_->full_scale(); }

 private:
  sim::SimCanImu imu_;
  std::optional<drivers::CanGyroSource> source_;
  std::unique_ptr<sim::EpochGyro> epoch_gyro_;
  std::string describe_;
};

drivers::CanGyroConfig can_gyro_config(const Config& cfg) {
  const CanGyroSection& s = cfg.can_gyro;
  drivers::CanGyroConfig c;
  c.field.id = static_cast<std::uint32_t>(s.id);
  c.field.extended = s.extended;
  c.field.byte_offset = s.offset;
  c.field.width_bits = s.width;
  c.field.is_signed = s.is_signed;
  c.field.big_endian = s.byte_order == ByteOrder::kBig;
  c.scale = s.scale;
  c.offset = s.rate_offset;
  c.sign = cfg.gyro.sign;
  c.stale_timeout = from_seconds(cfg.gyro.stale_timeout);
  c.max_frames_per_read = s.max_frames_per_read;
  return c;
}

std::string can_gyro_text(const CanGyroSection& s, int sign) {
  std::ostringstream d;
  d << "CAN gyro (id 0x" << std::hex << s.id << std::dec << (s.extended ? " extended" : "") << ", "
    << s.width << "-bit " << (s.is_signed ? "signed " : "unsigned ") << name_of(s.byte_order)
    << "-endian at byte " << s.offset << ", " << s.scale << " rad/s per LSB, sign " << sign << ")";
  return d.str();
}

Error in_can_gyro(const Config& cfg, Error e) {
  e.message = cfg.source + ": [can_gyro] " + e.message;
  return e;
}

}  // namespace

GyrodometryParams gyrodometry_params(const Config& cfg) {
  const GyroSection& g = cfg.gyro;
  GyrodometryParams p;
  if (simulated_gyro(cfg)) {
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
  c.stale_timeout = from_seconds(g.stale_timeout);
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
  auto made = model_gyro(g, robot);
  if (!made) return std::move(made).error();
  std::ostringstream d;
  d << "simulated " << name_of(g.model) << " gyro (seed " << g.seed << ")";
  return std::unique_ptr<GyroWiring>(
      std::make_unique<SimBackend>(std::move(made).value(), epoch, d.str()));
}

Result<std::unique_ptr<GyroWiring>> make_can_socketcan_gyro(const Config& cfg) {
  const drivers::CanGyroConfig c = can_gyro_config(cfg);
  drivers::SocketCanOptions o;
  o.interface = cfg.can_gyro.interface;
  // An exact-id filter: every other frame on the bus is dropped by the kernel.
  o.filters.push_back({c.field.id, c.field.extended ? 0x1FFFFFFFu : 0x7FFu, c.field.extended});
  auto bus = drivers::SocketCanBus::open(o);
  if (!bus) return in_can_gyro(cfg, std::move(bus).error());
  auto b = std::make_unique<CanSocketBackend>(
      std::move(bus).value(),
      can_gyro_text(cfg.can_gyro, cfg.gyro.sign) + " on SocketCAN " + o.interface);
  auto src = drivers::CanGyroSource::create(b->bus(), c);
  if (!src) return in_can_gyro(cfg, std::move(src).error());
  b->set_source(std::move(src).value());
  return std::unique_ptr<GyroWiring>(std::move(b));
}

Result<std::unique_ptr<GyroWiring>> make_can_sim_gyro(const Config& cfg, sim::SimRobot& robot,
                                                      const TimeNs* epoch) {
  const GyroSection& g = cfg.gyro;
  const CanGyroSection& s = cfg.can_gyro;
  const drivers::CanGyroConfig c = can_gyro_config(cfg);
  auto made = model_gyro(g, robot);
  if (!made) return std::move(made).error();
  // The simulated chip is mounted as [gyro] sign says: the decoder's sign undoes it.
  sim::SimCanImuOptions o{c.field.id,
                          c.field.extended,
                          c.field.byte_offset,
                          c.field.width_bits,
                          c.field.is_signed,
                          c.field.big_endian,
                          c.scale,
                          c.offset,
                          g.sign,
                          -1};
  if (s.sim_stop_after >= 0.0) o.stop_after = from_seconds(s.sim_stop_after);
  std::ostringstream d;
  d << can_gyro_text(s, g.sign) << ", from a simulated " << name_of(g.model) << " CAN IMU (seed "
    << g.seed << ")";
  auto b = std::make_unique<CanSimBackend>(std::move(made).value(), robot, o, epoch, d.str());
  auto src = drivers::CanGyroSource::create(b->port(), c);
  if (!src) return in_can_gyro(cfg, std::move(src).error());
  b->set_source(std::move(src).value());
  return std::unique_ptr<GyroWiring>(std::move(b));
}

}  // namespace odo::fw
