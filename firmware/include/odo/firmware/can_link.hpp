// CanLink: odometryd's [can] section composed (bus, broadcaster, --can-log writer); no thread of
// its own (the log writer has one). README "CAN protocol".
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <string_view>

#include "odo/firmware/can_broadcast.hpp"
#include "odo/firmware/can_log_writer.hpp"
#include "odo/firmware/config.hpp"
#include "odo/hal/can_bus.hpp"
#include "odo/hal/result.hpp"
#include "odo/loop/loop.hpp"
#include "odo/loop/recording_encoder.hpp"

namespace odo::sim {
class SimCanPort;
}

namespace odo::fw {

// CanLink: the [can] section wired up: the bus (simulated port or SocketCAN), the broadcaster
// registered on the loop, the optional candump log. Built at configure time.
class CanLink {
 public:
  ~CanLink();
  // create: [can] of cfg (the loop rate and [encoder] wheels_per_side with it); null (and ok) for
  // bus = "none" with no log; errors name the interface, and begin with cfg.source ("file: ")
  // when the config is at fault, with "--can-log FILE" when the log file is. virtual_time: the
  // log waits for its writer rather than dropping.
  static Result<std::unique_ptr<CanLink>> create(const Config& cfg, loop::OdometryLoop& loop,
                                                 const std::string& can_log,
                                                 bool virtual_time = false);
  // start: the log thread (call just before the loop runs).
  void start(std::int64_t epoch_ns);
  // send_final: final frames with the stopping status (loop thread, after run()).
  void send_final(const loop::LoopSnapshot& snap) noexcept { bc_->send_final(snap); }
  // close_log: writes what is queued and closes the log (joins its thread).
  void close_log();
  // finish: send_final, then close_log.
  void finish(const loop::LoopSnapshot& snap);
  const CanBroadcastCounters& counters() const noexcept { return bc_->counters(); }
  // set_fix_ring: absolute fixes received on this link go to `r` (configure time).
  void set_fix_ring(loop::FixRing* r) noexcept { bc_->set_fix_ring(r); }
  std::uint64_t log_written() const noexcept { return log_ ? log_->written() : 0; }
  std::uint64_t log_dropped() const noexcept { return log_ ? log_->ring().dropped() : 0; }
  const std::string& describe() const noexcept { return describe_; }
  // sim_port: the simulated bus port (bus = "sim"), for tests that inject commands; else null.
  sim::SimCanPort* sim_port() noexcept { return sim_port_; }

 private:
  CanLink() = default;
  sim::SimCanPort* sim_port_ = nullptr;
  std::unique_ptr<CanBus> bus_;
  std::unique_ptr<CanLogWriter> log_;
  std::unique_ptr<CanBroadcaster> bc_;
  std::string describe_;
};

}  // namespace odo::fw
