#include "encoder_backends.hpp"

#include <numbers>
#include <optional>
#include <sstream>

#include "odo/drivers/gpio_quadrature.hpp"
#include "odo/drivers/gpiod_parallel_bus.hpp"
#include "odo/drivers/hctl1100_encoder.hpp"
#include "odo/sim/hctl1100_model.hpp"
#include "odo/sim/robot.hpp"

namespace odo::fw {
namespace {

Error in_file(const Config& cfg, const std::string& section, Error e) {
  e.message = cfg.source + ": [" + section + "] " + e.message;
  return e;
}

drivers::Hctl1100Config driver_config(const Hctl1100Section& s, const Kinematics& k) {
  drivers::Hctl1100Config c;
  c.unit_left = 0;
  c.unit_right = 1;
  c.reverse_left = s.reverse_left;
  c.reverse_right = s.reverse_right;
  c.max_counts_per_s = max_counts_per_s(s, k.params());
  c.agree_window = s.agree_window;
  c.max_attempts = s.max_attempts;
  return c;
}

class GpioBackend final : public EncoderBackend {
 public:
  GpioBackend(std::unique_ptr<drivers::GpioQuadratureEncoder> e, std::string d)
      : enc_(std::move(e)), desc_(std::move(d)) {}
  EncoderSource& encoder() noexcept override { return *enc_; }
  const std::string& describe() const noexcept override { return desc_; }

 private:
  std::unique_ptr<drivers::GpioQuadratureEncoder> enc_;
  std::string desc_;
};

class HctlGpioBackend final : public EncoderBackend {
 public:
  HctlGpioBackend(std::unique_ptr<drivers::GpiodParallelBus> bus, drivers::Hctl1100Encoder enc,
                  std::string d)
      : bus_(std::move(bus)), enc_(std::move(enc)), desc_(std::move(d)) {}
  EncoderSource& encoder() noexcept override { return enc_; }
  const std::string& describe() const noexcept override { return desc_; }

 private:
  std::unique_ptr<drivers::GpiodParallelBus> bus_;  // the encoder points at it
  drivers::Hctl1100Encoder enc_;
  std::string desc_;
};

// HctlSimBackend: the chip models follow the simulated wheels before every bus cycle.
class HctlSimBackend final : public EncoderBackend, public sim::BusCycleHook {
 public:
  HctlSimBackend(const Hctl1100Section& s, sim::SimRobot& robot, Clock& clock, TimeNs epoch)
      : left_(s.latch == "lsb" ? sim::Hctl1100Model::Latch::kLsbLatch
                               : sim::Hctl1100Model::Latch::kNone),
        right_(left_),
        bus_(&left_, &right_),
        robot_(robot),
        clock_(clock),
        epoch_(epoch),
        cycle_(from_seconds(s.bus_cycle)) {
    bus_.set_hook(this);
  }
  void set_encoder(drivers::Hctl1100Encoder enc, std::string d) {
    enc_.emplace(std::move(enc));
    desc_ = std::move(d);
  }
  sim::SimHctlBus& bus() noexcept { return bus_; }
  void on_bus_cycle() noexcept override {
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
  EncoderSource& encoder() noexcept override { return *enc_; }
  const std::string& describe() const noexcept override { return desc_; }

 private:
  sim::Hctl1100Model left_, right_;
  sim::SimHctlBus bus_;
  sim::SimRobot& robot_;
  Clock& clock_;
  TimeNs epoch_;
  TimeNs cycle_;
  TimeNs extra_ = 0;
  TimeNs last_now_ = -1;
  std::optional<drivers::Hctl1100Encoder> enc_;
  std::string desc_;
};

}  // namespace

double max_counts_per_s(const Hctl1100Section& s, const KinematicParams& p) {
  // Counts per metre of wheel travel: Ce * n / (pi * Dn).
  return s.max_speed * p.counts_per_rev * p.gear_ratio / (std::numbers::pi * p.wheel_diameter);
}

Result<std::unique_ptr<EncoderBackend>> make_gpio_backend(const Config& cfg) {
  const GpioSection& s = cfg.gpio;
  drivers::GpioQuadratureConfig c;
  c.chip = s.chip;
  c.left = {static_cast<unsigned>(s.left_a), static_cast<unsigned>(s.left_b), s.left_index,
            s.reverse_left};
  c.right = {static_cast<unsigned>(s.right_a), static_cast<unsigned>(s.right_b), s.right_index,
             s.reverse_right};
  c.active_low = s.active_low;
  c.batch = s.batch;
  c.reorder_window = from_seconds(s.reorder_window);
  c.idle_check = from_seconds(s.idle_check);
  auto enc = drivers::GpioQuadratureEncoder::open(c);
  if (!enc) return in_file(cfg, "gpio", std::move(enc).error());
  std::ostringstream d;
  d << "GPIO quadrature on " << s.chip << " (left A/B " << s.left_a << "/" << s.left_b
    << ", right A/B " << s.right_a << "/" << s.right_b << "), libgpiod both-edge events, 4x";
  return std::unique_ptr<EncoderBackend>(new GpioBackend(std::move(enc).value(), d.str()));
}

Result<std::unique_ptr<EncoderBackend>> make_hctl_gpio_backend(const Config& cfg,
                                                               const Kinematics& k) {
  const Hctl1100Section& s = cfg.hctl1100;
  drivers::GpiodBusConfig b;
  b.chip = s.chip;
  for (int i = 0; i < 8; ++i) b.ad[static_cast<std::size_t>(i)] = static_cast<unsigned>(s.ad[i]);
  b.ale = static_cast<unsigned>(s.ale);
  b.oe = static_cast<unsigned>(s.oe);
  b.rw = static_cast<unsigned>(s.rw);
  b.cs = {static_cast<unsigned>(s.cs_left), static_cast<unsigned>(s.cs_right)};
  b.control_active_low = s.control_active_low;
  b.settle = from_seconds(s.settle);
  auto bus = drivers::GpiodParallelBus::open(b);
  if (!bus) return in_file(cfg, "hctl1100", std::move(bus).error());
  auto enc = drivers::Hctl1100Encoder::create(**bus, driver_config(s, k));
  if (!enc) return in_file(cfg, "hctl1100", std::move(enc).error());
  std::ostringstream d;
  d << "2 x HCTL-1100 (24-bit) on the GPIO bus of " << s.chip << ", jump limit "
    << max_counts_per_s(s, k.params()) << " counts/s";
  return std::unique_ptr<EncoderBackend>(
      new HctlGpioBackend(std::move(bus).value(), std::move(enc).value(), d.str()));
}

Result<std::unique_ptr<EncoderBackend>> make_hctl_sim_backend(const Config& cfg,
                                                              const Kinematics& k,
                                                              sim::SimRobot& robot, Clock& clock,
                                                              TimeNs epoch) {
  const Hctl1100Section& s = cfg.hctl1100;
  auto b = std::make_unique<HctlSimBackend>(s, robot, clock, epoch);
  auto enc = drivers::Hctl1100Encoder::create(b->bus(), driver_config(s, k));
  if (!enc) return in_file(cfg, "hctl1100", std::move(enc).error());
  std::ostringstream d;
  d << "2 x HCTL-1100 register model (24-bit, latch " << s.latch << ", bus cycle "
    << s.bus_cycle * 1e6 << " us) following the simulated robot";
  b->set_encoder(std::move(enc).value(), d.str());
  return std::unique_ptr<EncoderBackend>(std::move(b));
}

}  // namespace odo::fw
