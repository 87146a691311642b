#include "odo/firmware/can_broadcast.hpp"

#include <time.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <initializer_list>

#include "odo/drivers/socketcan_bus.hpp"
#include "odo/sim/sim_can_bus.hpp"

namespace odo::fw {

namespace {

// gyro_state: the Status frame's gyro_state (protocol/odometry.dbc): 0 no gyro, 1 fusing,
// 2 learning the bias (or waiting for the gyro's first sample), 3 gyro fault.
std::uint8_t gyro_state(const loop::LoopGyroStatus& g) noexcept {
  if (!g.enabled) return 0;
  // A gyro still starting is not a fault: the bias is not known yet either, so state 2.
  if ((g.fusion_flags & kFusionGyroFault) != 0 && g.gyro_flags != kGyroStarting) return 3;
  return g.bias_valid ? 1 : 2;
}

}  // namespace

// ---- candump -L log ----

CanLogWriter::~CanLogWriter() {
  stop();
}

Result<std::unique_ptr<CanLogWriter>> CanLogWriter::open(const std::string& path,
                                                         std::string iface) {
  std::FILE* f = std::fopen(path.c_str(), "w");
  if (f == nullptr)
    return make_error(
        Errc::kIo, path + ": cannot open the CAN log for writing (" + std::strerror(errno) + ")");
  std::unique_ptr<CanLogWriter> w(new CanLogWriter(f, std::move(iface)));
  w->buffer_.resize(1 << 16);
  std::setvbuf(f, w->buffer_.data(), _IOFBF, w->buffer_.size());
  return w;
}

void CanLogWriter::start(std::int64_t epoch_ns) {
  epoch_ns_ = epoch_ns;
  thread_ = std::thread([this] {
    while (!stop_.load(std::memory_order_acquire)) {
      drain();
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
  });
}

void CanLogWriter::drain() noexcept {
  CanFrame f;
  char line[96];
  bool any = false;
  while (ring_.pop(f)) {
    const std::size_t n =
        protocol::format_candump_line(line, sizeof line, epoch_ns_ + f.stamp, iface_.c_str(), f);
    if (n > 0 && std::fwrite(line, 1, n, file_) == n) {
      written_.fetch_add(1, std::memory_order_relaxed);
      any = true;
    }
  }
  // A reader tails the log (odomctl decode, umbmark record --can-log): what was drained is in
  // the file now, whole lines, not when the 64 KiB buffer fills (issue 35: 8 s, then steps).
  // One write call per drain (every 20 ms) rather than one a frame.
  if (any) std::fflush(file_);
}

void CanLogWriter::stop() {
  stop_.store(true, std::memory_order_release);
  if (thread_.joinable()) thread_.join();
  if (file_ != nullptr) {
    drain();
    std::fclose(file_);
    file_ = nullptr;
  }
}

// ---- CanBroadcaster ----

CanBroadcaster::CanBroadcaster(const CanBroadcastOptions& o, CanBus& bus,
                               loop::CommandQueue* commands, CanFrameRing* log) noexcept
    : o_(o), bus_(&bus), commands_(commands), log_(log) {}

void CanBroadcaster::send(const CanFrame& f, std::int64_t loop_time) noexcept {
  switch (bus_->send(f)) {
    case CanTx::kSent:
      ++c_.sent;
      // The frame is on its way: log it now, stamped with the loop time of its tick.
      if (log_ != nullptr) {
        CanFrame l = f;
        l.stamp = loop_time;
        log_frame(l);
      }
      break;
    case CanTx::kQueueFull:
      ++c_.dropped_queue_full;
      break;
    case CanTx::kLinkDown:
      ++c_.dropped_link_down;
      break;
    case CanTx::kError:
      ++c_.dropped_error;
      break;
  }
}

void CanBroadcaster::take_commands(CanFrame& f) noexcept {
  for (std::size_t i = 0; i < o_.max_rx_per_tick; ++i) {
    if (i > 0 && !bus_->receive(f)) break;
    int node = 0;
    protocol::Msg m{};
    if (!protocol::split_id(o_.base_id, f, node, m) || node != o_.node_id) continue;
    if (m == protocol::Msg::kFixPose || m == protocol::Msg::kFixSigma) {
      if (fixes_ != nullptr) take_fix(f, m);
      continue;
    }
    if (m != protocol::Msg::kSetPose || !o_.set_pose)
      continue;  // not for us (a SocketCAN filter normally keeps these out)
    protocol::SetPoseCmd cmd;
    if (!protocol::decode_set_pose(f, cmd)) {
      ++c_.set_pose_rejected;
      continue;
    }
    if (commands_ != nullptr && !commands_->post(loop::SetPose{Pose2{cmd.x, cmd.y, cmd.theta}})) {
      ++c_.set_pose_rejected;  // the loop's queue is full (it stopped taking commands)
      continue;
    }
    ++c_.set_pose_applied;
    ++pending_ack_;
  }
}

void CanBroadcaster::take_fix(const CanFrame& f, protocol::Msg m) noexcept {
  if (m == protocol::Msg::kFixPose) {
    have_fix_half_ = protocol::decode_fix_pose(f, fix_half_);
    if (!have_fix_half_) ++c_.fixes_refused;
    return;
  }
  protocol::FixMsg fm = fix_half_;
  if (!have_fix_half_ || !protocol::decode_fix_sigma(f, fm) || fm.seq != fix_half_.seq) {
    ++c_.fixes_refused;
    return;
  }
  have_fix_half_ = false;
  calib::PoseFix p;
  p.t = rx_stamp_ - from_seconds(fm.age);
  p.x = fm.x;
  p.y = fm.y;
  if (fm.sigma_theta > 0.0) p.theta = fm.theta;
  p.sigma_xy = fm.sigma_xy;
  p.sigma_theta = fm.sigma_theta;
  if (fixes_->push(p))
    ++c_.fixes_forwarded;
  else
    ++c_.fixes_refused;
}

void CanBroadcaster::send_pose_group(const loop::LoopSnapshot& s) noexcept {
  if (sent_any_pose_) ++seq_;
  sent_any_pose_ = true;
  const protocol::PoseMsg p{s.pose.x, s.pose.y, s.pose.theta, seq_};
  CanFrame f;
  protocol::encode_pose_x(id(protocol::Msg::kPoseX), p, f);
  send(f, s.loop_time);
  protocol::encode_pose_y_theta(id(protocol::Msg::kPoseYTheta), p, f);
  send(f, s.loop_time);
}

void CanBroadcaster::send_velocity(const loop::LoopSnapshot& s) noexcept {
  CanFrame f;
  protocol::encode_velocity(id(protocol::Msg::kVelocity), protocol::VelocityMsg{s.v, s.w, seq_}, f);
  send(f, s.loop_time);
}

void CanBroadcaster::send_uncertainty(const loop::LoopSnapshot& s) noexcept {
  protocol::UncertaintyMsg u;
  u.seq = seq_;
  if (s.has_cov) {
    u.sigma_x = std::sqrt(std::max(0.0, s.cov[0]));
    u.sigma_y = std::sqrt(std::max(0.0, s.cov[4]));
    u.sigma_theta = std::sqrt(std::max(0.0, s.cov[8]));
    const double sxy = u.sigma_x * u.sigma_y;
    u.rho_xy = sxy > 0.0 ? s.cov[1] / sxy : 0.0;
  } else {
    u.sigma_x = u.sigma_y = u.sigma_theta = std::nan("");  // unknown: sent as the maximum
  }
  CanFrame f;
  protocol::encode_uncertainty(id(protocol::Msg::kUncertainty), u, f);
  send(f, s.loop_time);
}

void CanBroadcaster::send_status(const loop::LoopSnapshot& s, bool stopping) noexcept {
  protocol::StatusMsg m;
  m.encoder_flags = static_cast<std::uint8_t>(s.encoder_flags & 0xFFu);
  m.calibration_state = static_cast<std::uint8_t>(s.calibration_state);
  m.stopping = stopping;
  m.gyro_state = gyro_state(s.gyro);
  const FusionCounters& c = s.gyro.fusion;
  m.gyro_events =
      static_cast<std::uint8_t>((c.disagreements + c.speed_events + c.accel_events) & 7u);
  m.set_pose_ack = ack_;
  m.missed_deadlines = s.stats.missed_deadlines > 0xFFFFFFFFu
                           ? 0xFFFFFFFFu
                           : static_cast<std::uint32_t>(s.stats.missed_deadlines);
  m.uptime = to_seconds(s.loop_time);
  CanFrame f;
  protocol::encode_status(id(protocol::Msg::kStatus), m, f);
  send(f, s.loop_time);
}

void CanBroadcaster::send_timing(const loop::LoopSnapshot& s) noexcept {
  protocol::TimingMsg t;
  t.wakeup_p99 = to_seconds(s.stats.wakeup_latency.p99);
  t.wakeup_max = to_seconds(s.stats.wakeup_latency_max);
  t.compute_max = to_seconds(s.stats.compute_max);
  const std::uint64_t d = c_.dropped();
  t.tx_dropped = d > 0xFFFFFFFFu ? 0xFFFFFFFFu : static_cast<std::uint32_t>(d);
  CanFrame f;
  protocol::encode_timing(id(protocol::Msg::kTiming), t, f);
  send(f, s.loop_time);
}

void CanBroadcaster::send_encoder_faults(const loop::LoopSnapshot& s) noexcept {
  CanFrame f;
  protocol::encode_encoder_faults(id(protocol::Msg::kEncoderFaults), s.encoder_counters, f);
  send(f, s.loop_time);
}

void CanBroadcaster::on_tick(const loop::LoopSnapshot& s) noexcept {
  // Commands taken last tick were applied at the start of this one: acknowledge them now, so a
  // receiver that sees the ack also sees the new pose in the same or a later pose group.
  ack_ = static_cast<std::uint8_t>(ack_ + pending_ack_);
  pending_ack_ = 0;
  // The first receive is made here: on nearly every tick it finds nothing, and the command loop
  // (take_commands) is not entered.
  if ((o_.set_pose || fixes_ != nullptr) && o_.max_rx_per_tick > 0) {
    rx_stamp_ = s.stamp;
    CanFrame f;
    if (bus_->receive(f)) take_commands(f);
  }
  // Most ticks send nothing (19 of 20 at the default rates): one unsigned comparison tells, and
  // five divisions are saved. A tick number that went back, or repeated, wraps around and fails
  // it, so the result is always that of the modulo checks in send_due.
  if (s.tick - quiet_after_ - 1 >= quiet_span_) send_due(s);
}

void CanBroadcaster::send_due(const loop::LoopSnapshot& s) noexcept {
  const std::uint64_t t = s.tick;
  const CanDivisors& d = o_.div;
  if (d.pose != 0 && t % d.pose == 0) send_pose_group(s);
  if (d.velocity != 0 && t % d.velocity == 0) send_velocity(s);
  if (d.uncertainty != 0 && t % d.uncertainty == 0) send_uncertainty(s);
  if (d.status != 0 && t % d.status == 0) {
    // The counters behind the Status frame's encoder flags, at its rate and just before it.
    send_encoder_faults(s);
    send_status(s, false);
  }
  if (d.timing != 0 && t % d.timing == 0) send_timing(s);
  // The next tick that is a multiple of an enabled divisor; none enabled: never.
  std::uint64_t next = UINT64_MAX;
  for (const std::uint32_t div : {d.pose, d.velocity, d.uncertainty, d.status, d.timing}) {
    if (div != 0) next = std::min(next, (t / div + 1) * div);
  }
  quiet_after_ = t;
  quiet_span_ = next - t - 1;
}

void CanBroadcaster::send_final(const loop::LoopSnapshot& s) noexcept {
  ack_ = static_cast<std::uint8_t>(ack_ + pending_ack_);
  pending_ack_ = 0;
  send_pose_group(s);
  send_velocity(s);
  send_uncertainty(s);
  send_timing(s);
  send_encoder_faults(s);
  send_status(s, true);
}

// ---- CanLink ----

namespace {

// open_socket_bus: the daemon's SocketCAN socket; it receives only the commands addressed to
// this node (set-pose when enabled, the absolute fixes, dropped unless [selfcal] is enabled).
Result<std::unique_ptr<drivers::SocketCanBus>> open_socket_bus(const CanSection& s) {
  drivers::SocketCanOptions so;
  so.interface = s.interface;
  so.reopen_period = s.reopen_period;
  const auto id = [&](protocol::Msg m) {
    return protocol::frame_id(static_cast<std::uint32_t>(s.base_id), s.node_id, m);
  };
  if (s.set_pose)
    so.filters.push_back(drivers::CanFilter{id(protocol::Msg::kSetPose), 0x7FF, false});
  for (const protocol::Msg m : {protocol::Msg::kFixPose, protocol::Msg::kFixSigma})
    so.filters.push_back(drivers::CanFilter{id(m), 0x7FF, false});
  return drivers::SocketCanBus::open(so);
}

// broadcast_options: [can] as the broadcaster takes it (rates as loop-tick divisors).
CanBroadcastOptions broadcast_options(const CanSection& s, double loop_hz, bool virtual_time) {
  CanBroadcastOptions o;
  o.base_id = static_cast<std::uint32_t>(s.base_id);
  o.node_id = s.node_id;
  o.set_pose = s.set_pose;
  o.lossless_log = virtual_time;
  auto div = [&](double hz) {
    const std::int64_t d = protocol::divisor_for(loop_hz, hz);
    return d > 0 ? static_cast<std::uint32_t>(d) : 0u;
  };
  o.div = CanDivisors{div(s.pose_hz), div(s.velocity_hz), div(s.uncertainty_hz), div(s.status_hz),
                      div(s.timing_hz)};
  return o;
}

}  // namespace

CanLink::~CanLink() {
  if (log_) log_->stop();
}

Result<std::unique_ptr<CanLink>> CanLink::create(const CanSection& s, double loop_hz,
                                                 loop::OdometryLoop& loop,
                                                 const std::string& can_log, bool virtual_time,
                                                 std::string_view config_source) {
  // The config's faults are reported under its file name; the log file's under the option.
  auto config_error = [&](Error e) {
    if (!config_source.empty()) e.message = std::string(config_source) + ": " + e.message;
    return e;
  };
  std::unique_ptr<CanLink> link(new CanLink());
  if (s.bus == CanBusKind::kNone) {
    if (!can_log.empty())
      return config_error(make_error(Errc::kInvalidArgument,
                                     "can.bus = \"none\": --can-log needs a CAN bus (\"sim\" or "
                                     "\"socketcan\")"));
    return std::unique_ptr<CanLink>();
  }
  std::string iface;
  if (s.bus == CanBusKind::kSocketCan) {
    auto bus = open_socket_bus(s);
    if (!bus) return config_error(std::move(bus).error());
    link->bus_ = std::move(bus).value();
    iface = s.interface;
  } else {
    auto port = std::make_unique<sim::SimCanPort>();
    port->connect_wire();  // an idle simulated bus: the wire takes every frame as it is sent
    link->sim_port_ = port.get();
    link->bus_ = std::move(port);
    iface = "sim0";
  }
  if (!can_log.empty()) {
    auto w = CanLogWriter::open(can_log, iface);
    if (!w) return make_error(w.error().code, "--can-log " + w.error().message);
    link->log_ = std::move(w).value();
  }
  const CanBroadcastOptions o = broadcast_options(s, loop_hz, virtual_time);
  link->bc_ = std::make_unique<CanBroadcaster>(o, *link->bus_, &loop.commands(),
                                               link->log_ ? &link->log_->ring() : nullptr);
  if (!loop.add_observer(link->bc_.get()))
    return config_error(make_error(Errc::kInvalidArgument, "can: too many loop observers"));
  char idtxt[16];
  std::snprintf(idtxt, sizeof idtxt, "0x%03X",
                protocol::frame_id(o.base_id, o.node_id, protocol::Msg::kPoseX));
  link->describe_ =
      (s.bus == CanBusKind::kSocketCan ? "SocketCAN " + s.interface : std::string("simulated bus")) +
      ", node " + std::to_string(s.node_id) + ", ids from " + idtxt +
      (s.set_pose ? ", set-pose on" : ", set-pose off") +
      (can_log.empty() ? std::string() : ", log " + can_log);
  return link;
}

void CanLink::start(std::int64_t epoch_ns) {
  if (log_) log_->start(epoch_ns);
}

void CanLink::close_log() {
  if (log_) log_->stop();
}

void CanLink::finish(const loop::LoopSnapshot& snap) {
  send_final(snap);
  close_log();
}

}  // namespace odo::fw
