#include "encoder_backends.hpp"

#include <cstdio>
#include <numbers>
#include <optional>
#include <sstream>

#include "odo/drivers/can_encoder.hpp"
#include "odo/drivers/gpio_quadrature.hpp"
#include "odo/drivers/gpiod_parallel_bus.hpp"
#include "odo/drivers/hctl1100_encoder.hpp"
#include "odo/drivers/serial_port.hpp"
#include "odo/drivers/socketcan_bus.hpp"
#include "odo/firmware/serial_peer.hpp"
#include "odo/sim/robot_buses.hpp"

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

// HctlSimBackend: the real driver reading sim_hal's register models, which follow the robot.
class HctlSimBackend final : public EncoderBackend {
 public:
  HctlSimBackend(const Hctl1100Section& s, sim::SimRobot& robot, Clock& clock, TimeNs epoch)
      : chips_(s.latch == HctlLatch::kLsb ? sim::Hctl1100Model::Latch::kLsbLatch
                                          : sim::Hctl1100Model::Latch::kNone,
               from_seconds(s.bus_cycle), robot, clock, epoch) {}
  void set_encoder(drivers::Hctl1100Encoder enc, std::string d) {
    enc_.emplace(std::move(enc));
    desc_ = std::move(d);
  }
  sim::SimHctlBus& bus() noexcept { return chips_.bus(); }
  EncoderSource& encoder() noexcept override { return *enc_; }
  const std::string& describe() const noexcept override { return desc_; }

 private:
  sim::RobotHctlBus chips_;
  std::optional<drivers::Hctl1100Encoder> enc_;
  std::string desc_;
};

class CanSocketBackend final : public EncoderBackend {
 public:
  CanSocketBackend(std::unique_ptr<drivers::SocketCanBus> bus, std::string d)
      : bus_(std::move(bus)), desc_(std::move(d)) {}
  void set_encoder(drivers::CanEncoderSource enc) { enc_.emplace(std::move(enc)); }
  drivers::SocketCanBus& bus() noexcept { return *bus_; }
  EncoderSource& encoder() noexcept override { return *enc_; }
  const std::string& describe() const noexcept override { return desc_; }

 private:
  std::unique_ptr<drivers::SocketCanBus> bus_;  // the encoder points at it
  std::optional<drivers::CanEncoderSource> enc_;
  std::string desc_;
};

sim::RobotOdriveOptions odrive_options(const CanEncoderSection& s) {
  sim::RobotOdriveOptions o;
  o.node_left = static_cast<std::uint32_t>(s.node_left);
  o.node_right = static_cast<std::uint32_t>(s.node_right);
  o.period = from_seconds(s.sim_period);
  o.stop_left_after = s.sim_stop_left_after < 0 ? -1 : from_seconds(s.sim_stop_left_after);
  o.stop_right_after = s.sim_stop_right_after < 0 ? -1 : from_seconds(s.sim_stop_right_after);
  return o;
}

// CanSimBackend: before each read, sim_hal's ODrive axes publish every cyclic message due
// since the last read, then the real driver reads the port.
class CanSimBackend final : public EncoderBackend, public EncoderSource {
 public:
  CanSimBackend(const CanEncoderSection& s, sim::SimRobot& robot, TimeNs epoch)
      : axes_(odrive_options(s), robot, epoch) {}
  void set_encoder(drivers::CanEncoderSource enc, std::string d) {
    enc_.emplace(std::move(enc));
    desc_ = std::move(d);
  }
  sim::SimCanPort& port() noexcept { return axes_.port(); }
  EncoderSample read(TimeNs now) noexcept override {
    axes_.publish_until(now);
    return enc_->read(now);
  }
  int counter_bits() const noexcept override { return enc_->counter_bits(); }
  EncoderSource& encoder() noexcept override { return *this; }
  const std::string& describe() const noexcept override { return desc_; }

 private:
  sim::RobotOdriveBus axes_;
  std::optional<drivers::CanEncoderSource> enc_;
  std::string desc_;
};

std::string layout_text(const drivers::CanCountLayout& l) {
  char b[96];
  std::snprintf(b, sizeof b, "id 0x%X%s bytes %d..%d", l.id, l.extended ? " (29-bit)" : "",
                l.byte_offset, l.byte_offset + l.width_bits / 8 - 1);
  return b;
}

// side_text: the side's wheels' layouts, "id 0x00A bytes 0..3" or "[id 0x00A ..., id 0x04A ...]".
std::string side_text(const drivers::CanEncoderConfig& c, int side) {
  const int n = c.wheels.wheels_per_side;
  std::string t = n > 1 ? "[" : "";
  for (int k = 0; k < n; ++k)
    t += (k > 0 ? ", " : "") + layout_text(drivers::can_wheel_layout(c, 2 * k + side));
  return t + (n > 1 ? "]" : "");
}

std::string can_text(const CanEncoderSection& s, const drivers::CanEncoderConfig& c) {
  std::ostringstream d;
  if (s.protocol == CanEncoderProtocol::kOdrive) {
    d << "ODrive CAN Simple encoder counts (nodes ";
    for (int k = 0; k < 2 * s.wheels_per_side; ++k)
      d << (k == s.wheels_per_side ? "/" : (k > 0 ? "," : ""))
        << (drivers::can_wheel_layout(
                c, k < s.wheels_per_side ? 2 * k : 2 * (k - s.wheels_per_side) + 1)
                .id >>
            5);
    d << ", ";
  } else {
    d << "generic CAN counts (";
  }
  if (s.wheels_per_side > 1) d << s.wheels_per_side << " wheels per side, ";
  d << "left " << side_text(c, 0) << ", right " << side_text(c, 1) << ", " << c.left.width_bits
    << "-bit " << (c.left.is_signed ? "signed" : "unsigned") << " "
    << (c.left.big_endian ? "big" : "little") << " endian), stale after " << s.timeout * 1e3
    << " ms, jump limit " << c.max_counts_per_s << " counts/s"
    << (s.request_rate > 0 ? ", requests at " + std::to_string(s.request_rate) + " Hz" : "");
  return d.str();
}

class SerialTtyBackend final : public EncoderBackend {
 public:
  SerialTtyBackend(std::unique_ptr<drivers::SerialPort> port, const protocol::SerialSourceConfig& c,
                   std::string d)
      : port_(std::move(port)), source_(*port_, c), desc_(std::move(d)) {}
  EncoderSource& encoder() noexcept override { return source_; }
  const std::string& describe() const noexcept override { return desc_; }

 private:
  std::unique_ptr<drivers::SerialPort> port_;  // the source points at it
  protocol::SerialCountsSource source_;
  std::string desc_;
};

// SerialSimBackend: a simulated controller (SerialPeerModel) following the robot, its bytes in a
// fixed ring read by the real source: before each read the controller sends what is due.
class SerialSimBackend final : public EncoderBackend, public EncoderSource, public ByteLink {
 public:
  SerialSimBackend(const Config& cfg, const Kinematics& k, sim::SimRobot& robot, TimeNs epoch,
                   std::string d)
      : model_(cfg.serial.protocol, cfg.encoder.side.wheels_per_side),
        protocol_(cfg.serial.protocol),
        robot_(robot),
        epoch_(epoch),
        period_(from_seconds(cfg.serial.sim_period)),
        source_(*this, serial_source_config(cfg.serial, cfg.encoder.side, k.params())),
        desc_(std::move(d)) {}
  EncoderSample read(TimeNs now) noexcept override {
    now_ = now;
    if (protocol_ == SerialProtocol::kDiffodom) {
      for (const TimeNs t = now - epoch_; next_ <= t; next_ += period_) send_at(next_);
    }
    if (now - epoch_ > robot_.time()) robot_.advance_to(now - epoch_);
    return source_.read(now);
  }
  int counter_bits() const noexcept override { return source_.counter_bits(); }
  int read(std::span<std::uint8_t> out, TimeNs& /*arrival: the read's*/) noexcept override {
    std::size_t n = 0;
    for (; n < out.size() && tail_ != head_; ++n, ++tail_) out[n] = ring_[tail_ % ring_.size()];
    return static_cast<int>(n);
  }
  bool write(std::span<const std::uint8_t> data) noexcept override {
    // The board answers at once, with its counts of the moment of the request.
    model_.on_host_bytes(data);
    send_at(now_ - epoch_);
    return true;
  }
  bool reopen() noexcept override { return true; }
  EncoderSource& encoder() noexcept override { return *this; }
  const std::string& describe() const noexcept override { return desc_; }

 private:
  void send_at(TimeNs t) noexcept {
    if (t > robot_.time()) robot_.advance_to(t);
    std::array<std::uint8_t, SerialPeerModel::kMaxOut> buf{};
    const std::size_t n = model_.sample(t, robot_.counts_left(), robot_.counts_right(), buf);
    // A full ring drops the newest bytes, as a UART's would: the source sees a gap.
    for (std::size_t i = 0; i < n && head_ - tail_ < ring_.size(); ++i, ++head_)
      ring_[head_ % ring_.size()] = buf[i];
  }

  SerialPeerModel model_;
  SerialProtocol protocol_;
  sim::SimRobot& robot_;
  TimeNs epoch_;
  TimeNs period_;
  TimeNs next_ = 0;
  TimeNs now_ = 0;
  std::array<std::uint8_t, 4096> ring_{};
  std::size_t head_ = 0;
  std::size_t tail_ = 0;
  protocol::SerialCountsSource source_;
  std::string desc_;
};

std::string serial_text(const SerialSection& s) {
  std::ostringstream d;
  d << name_of(s.protocol) << " counts over a serial line (" << s.bits_left << "/" << s.bits_right
    << "-bit counters, stale after " << s.timeout * 1e3 << " ms";
  if (s.protocol == SerialProtocol::kArduinoBridge) d << ", polled at " << s.poll_rate << " Hz";
  d << ")";
  return d.str();
}

}  // namespace

protocol::SerialSourceConfig serial_source_config(const SerialSection& s, const SideWheelsConfig& w,
                                                  const KinematicParams& p) {
  protocol::SerialSourceConfig c;
  c.wheels = w;
  c.protocol = s.protocol == SerialProtocol::kDiffodom ? protocol::SerialProtocol::kDiffodom
                                                       : protocol::SerialProtocol::kArduinoBridge;
  c.bits_left = s.bits_left;
  c.bits_right = s.bits_right;
  c.reverse_left = s.reverse_left;
  c.reverse_right = s.reverse_right;
  c.timeout = from_seconds(s.timeout);
  c.reopen_period = from_seconds(s.reopen_period);
  c.poll_period = from_seconds(1.0 / s.poll_rate);
  c.max_counts_per_s = s.max_speed * counts_per_metre(p);
  c.clock_window = from_seconds(s.clock_window);
  return c;
}

Result<std::unique_ptr<EncoderBackend>> make_serial_tty_backend(const Config& cfg,
                                                                const Kinematics& k) {
  const SerialSection& s = cfg.serial;
  auto port = drivers::SerialPort::open(s.device, s.baud, from_seconds(s.reopen_period));
  if (!port) {
    Error e = std::move(port).error();
    e.message = s.device_where + " " + e.message;
    return e;
  }
  std::ostringstream d;
  d << serial_text(s) << " on " << s.device << " at " << s.baud << " baud";
  return std::unique_ptr<EncoderBackend>(new SerialTtyBackend(
      std::move(port).value(), serial_source_config(s, cfg.encoder.side, k.params()), d.str()));
}

Result<std::unique_ptr<EncoderBackend>> make_serial_sim_backend(const Config& cfg,
                                                                const Kinematics& k,
                                                                sim::SimRobot& robot,
                                                                TimeNs epoch) {
  std::ostringstream d;
  d << serial_text(cfg.serial) << ", from a simulated controller";
  if (cfg.serial.protocol == SerialProtocol::kDiffodom)
    d << " every " << cfg.serial.sim_period * 1e3 << " ms";
  d << " following the simulated robot";
  return std::unique_ptr<EncoderBackend>(new SerialSimBackend(cfg, k, robot, epoch, d.str()));
}

drivers::CanEncoderConfig can_encoder_config(const CanEncoderSection& s, const SideWheelsConfig& w,
                                             const KinematicParams& p) {
  drivers::CanEncoderConfig c;
  c.wheels = w;  // counter_bits: set by the source from the layouts
  c.wheels.wheels_per_side = s.wheels_per_side;
  for (int k = 0; k < s.wheels_per_side; ++k) {
    const auto m = static_cast<std::size_t>(k > 0 ? k - 1 : 0);
    for (int side = 0; side < 2; ++side) {
      drivers::CanCountLayout& l =
          k == 0 ? (side == 0 ? c.left : c.right) : (side == 0 ? c.more_left[m] : c.more_right[m]);
      if (s.protocol == CanEncoderProtocol::kOdrive) {
        const int node = k == 0 ? (side == 0 ? s.node_left : s.node_right)
                                : (side == 0 ? s.more_node_left[m] : s.more_node_right[m]);
        l = drivers::odrive_count_layout(static_cast<std::uint32_t>(node));
        continue;
      }
      l.id =
          static_cast<std::uint32_t>(k == 0 ? (side == 0 ? s.left_id : s.right_id)
                                            : (side == 0 ? s.more_left_id[m] : s.more_right_id[m]));
      l.extended = s.extended;
      l.byte_offset = k == 0 ? (side == 0 ? s.left_offset : s.right_offset)
                             : (side == 0 ? s.more_left_offset[m] : s.more_right_offset[m]);
      l.width_bits = s.width;
      l.is_signed = s.is_signed;
      l.big_endian = s.byte_order == ByteOrder::kBig;
    }
  }
  c.reverse_left = s.reverse_left;
  c.reverse_right = s.reverse_right;
  c.timeout = from_seconds(s.timeout);
  c.max_counts_per_s = s.max_speed * counts_per_metre(p);
  c.max_frames_per_read = s.max_frames_per_read;
  c.request_period = s.request_rate > 0 ? from_seconds(1.0 / s.request_rate) : 0;
  return c;
}

Result<std::unique_ptr<EncoderBackend>> make_can_socketcan_backend(const Config& cfg,
                                                                   const Kinematics& k) {
  const CanEncoderSection& s = cfg.can_encoder;
  const drivers::CanEncoderConfig c = can_encoder_config(s, cfg.encoder.side, k.params());
  drivers::SocketCanOptions o;
  o.interface = s.interface;
  for (int i = 0; i < drivers::can_wheel_count(c); ++i) {
    // Exact-id filters: every other frame is dropped by the kernel.
    const drivers::CanCountLayout& l = drivers::can_wheel_layout(c, i);
    o.filters.push_back({l.id, l.extended ? 0x1FFFFFFFu : 0x7FFu, l.extended});
  }
  auto bus = drivers::SocketCanBus::open(o);
  if (!bus) return in_file(cfg, "can_encoder", std::move(bus).error());
  auto b = std::make_unique<CanSocketBackend>(std::move(bus).value(),
                                              can_text(s, c) + " on SocketCAN " + s.interface);
  auto enc = drivers::CanEncoderSource::create(b->bus(), c);
  if (!enc) return in_file(cfg, "can_encoder", std::move(enc).error());
  b->set_encoder(std::move(enc).value());
  return std::unique_ptr<EncoderBackend>(std::move(b));
}

Result<std::unique_ptr<EncoderBackend>> make_can_sim_backend(const Config& cfg, const Kinematics& k,
                                                             sim::SimRobot& robot, TimeNs epoch) {
  const CanEncoderSection& s = cfg.can_encoder;
  if (s.protocol != CanEncoderProtocol::kOdrive)
    return make_error(Errc::kInvalidArgument,
                      cfg.source +
                          ": [can_encoder] bus = \"sim\" simulates ODrive controllers: "
                          "set protocol = \"odrive\"");
  const drivers::CanEncoderConfig c = can_encoder_config(s, cfg.encoder.side, k.params());
  auto b = std::make_unique<CanSimBackend>(s, robot, epoch);
  auto enc = drivers::CanEncoderSource::create(b->port(), c);
  if (!enc) return in_file(cfg, "can_encoder", std::move(enc).error());
  std::ostringstream d;
  d << can_text(s, c) << ", from 2 simulated ODrive axes every " << s.sim_period * 1e3
    << " ms following the simulated robot";
  b->set_encoder(std::move(enc).value(), d.str());
  return std::unique_ptr<EncoderBackend>(std::move(b));
}

double max_counts_per_s(const Hctl1100Section& s, const KinematicParams& p) {
  return s.max_speed * counts_per_metre(p);
}

Result<std::unique_ptr<EncoderBackend>> make_gpio_backend(const Config& cfg) {
  const GpioSection& s = cfg.gpio;
  drivers::GpioQuadratureConfig c;
  c.chip = s.chip;
  c.left = {static_cast<unsigned>(s.left_a), static_cast<unsigned>(s.left_b), s.left_index,
            s.reverse_left};
  c.right = {static_cast<unsigned>(s.right_a), static_cast<unsigned>(s.right_b), s.right_index,
             s.reverse_right};
  c.wheels = cfg.encoder.side;
  c.wheels.wheels_per_side = s.wheels_per_side;
  for (std::size_t k = 0; k + 1 < static_cast<std::size_t>(s.wheels_per_side); ++k) {
    c.more_left[k] = {static_cast<unsigned>(s.more_left_a[k]),
                      static_cast<unsigned>(s.more_left_b[k]), -1, s.reverse_left};
    c.more_right[k] = {static_cast<unsigned>(s.more_right_a[k]),
                       static_cast<unsigned>(s.more_right_b[k]), -1, s.reverse_right};
  }
  c.active_low = s.active_low;
  c.batch = s.batch;
  c.reorder_window = from_seconds(s.reorder_window);
  c.idle_check = from_seconds(s.idle_check);
  auto enc = drivers::GpioQuadratureEncoder::open(c);
  if (!enc) return in_file(cfg, "gpio", std::move(enc).error());
  std::ostringstream d;
  d << "GPIO quadrature on " << s.chip << " (left A/B " << s.left_a << "/" << s.left_b
    << ", right A/B " << s.right_a << "/" << s.right_b;
  for (std::size_t k = 0; k + 1 < static_cast<std::size_t>(s.wheels_per_side); ++k)
    d << "; wheel " << k + 2 << ": left A/B " << s.more_left_a[k] << "/" << s.more_left_b[k]
      << ", right A/B " << s.more_right_a[k] << "/" << s.more_right_b[k];
  d << "), libgpiod both-edge events, 4x";
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
  d << "2 x HCTL-1100 register model (24-bit, latch " << name_of(s.latch) << ", bus cycle "
    << s.bus_cycle * 1e6 << " us) following the simulated robot";
  b->set_encoder(std::move(enc).value(), d.str());
  return std::unique_ptr<EncoderBackend>(std::move(b));
}

}  // namespace odo::fw
