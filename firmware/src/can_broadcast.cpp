#include "odo/firmware/can_broadcast.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <initializer_list>

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

CanBroadcaster::CanBroadcaster(const CanBroadcastOptions& o, CanBus& bus,
                               loop::CommandQueue* commands, CanFrameRing* log) noexcept
    : o_(o), bus_(&bus), log_(log), rx_(o, bus, commands, c_) {}

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
  protocol::encode_velocity(id(protocol::Msg::kVelocity), protocol::VelocityMsg{s.v, s.omega, seq_},
                            f);
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

void CanBroadcaster::send_side_wheels(const loop::LoopSnapshot& s) noexcept {
  const auto n = static_cast<std::uint8_t>(o_.wheels_per_side);
  CanFrame f;
  protocol::encode_side_wheels(id(protocol::Msg::kSideWheels),
                               protocol::SideWheelsMsg{s.encoder_flags, n, s.encoder_counters}, f);
  send(f, s.loop_time);
}

void CanBroadcaster::on_tick(const loop::LoopSnapshot& s) noexcept {
  // Commands taken last tick were applied at the start of this one: acknowledge them now, so a
  // receiver that sees the ack also sees the new pose in the same or a later pose group.
  ack_ = static_cast<std::uint8_t>(ack_ + rx_.take_posted());
  rx_.receive(s.stamp);
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
    // The counters behind the Status frame's encoder flags, at its rate and just before it;
    // with several wheels per side, the flags (bits 8..10) that Status's byte cannot carry.
    send_encoder_faults(s);
    if (o_.wheels_per_side > 1) send_side_wheels(s);
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
  ack_ = static_cast<std::uint8_t>(ack_ + rx_.take_posted());
  send_pose_group(s);
  send_velocity(s);
  send_uncertainty(s);
  send_timing(s);
  send_encoder_faults(s);
  if (o_.wheels_per_side > 1) send_side_wheels(s);
  send_status(s, true);
}

}  // namespace odo::fw
