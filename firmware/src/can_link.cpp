#include "odo/firmware/can_link.hpp"

#include <cstdint>
#include <cstdio>
#include <initializer_list>

#include "odo/drivers/socketcan_bus.hpp"
#include "odo/sim/sim_can_bus.hpp"

namespace odo::fw {

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

Result<std::unique_ptr<CanLink>> CanLink::create(const Config& cfg, loop::OdometryLoop& loop,
                                                 const std::string& can_log, bool virtual_time) {
  const CanSection& s = cfg.can;
  const std::string_view config_source = cfg.source;
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
  CanBroadcastOptions o = broadcast_options(s, cfg.loop.rate_hz, virtual_time);
  o.wheels_per_side = cfg.encoder.side.wheels_per_side;
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
