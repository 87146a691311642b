#include "odo/board/slcan_link.hpp"

#include "odo/board/system.hpp"

namespace odo::board {

CanTx SlcanBus::send(const CanFrame& f) noexcept {
  char line[protocol::kSlcanLineMax];
  const std::size_t n = protocol::encode_slcan(f, line);
  return uart_->write(line, n) ? CanTx::kSent : CanTx::kQueueFull;
}

bool SlcanBus::receive(CanFrame& out) noexcept {
  char c = 0;
  while (uart_->read(c)) {
    const auto e = dec_.push(c);
    if (e == protocol::SlcanDecoder::Event::kFrame) {
      out = dec_.frame();
      return true;
    }
    if (e == protocol::SlcanDecoder::Event::kError) ++bad_lines_;
    // Adapter commands (slcand's "C", "S6", "O") need no answer: the kernel reads none.
  }
  return false;
}

void PoseBroadcaster::send(const CanFrame& f) noexcept {
  if (bus_->send(f) == CanTx::kSent)
    ++sent_;
  else
    ++dropped_;
}

void PoseBroadcaster::take_commands() noexcept {
  CanFrame f;
  for (int i = 0; i < 8 && bus_->receive(f); ++i) {
    int node = 0;
    protocol::Msg m{};
    if (!protocol::split_id(o_.base_id, f, node, m) || node != o_.node_id ||
        m != protocol::Msg::kSetPose)
      continue;
    SetPose cmd;
    if (!protocol::decode_set_pose(f, cmd)) continue;
    if (commands_->post(cmd)) {
      ++set_pose_applied_;
      ++pending_ack_;
    }
  }
}

void PoseBroadcaster::on_tick(const loop::LoopSnapshot& s) noexcept {
  watchdog_kick();
  // Commands taken last tick were applied at the top of this one: acknowledged from now on.
  ack_ = static_cast<std::uint8_t>(ack_ + pending_ack_);
  pending_ack_ = 0;
  take_commands();
  if (o_.pose_div != 0 && s.tick % o_.pose_div == 0) send_pose_group(s);
  if (o_.status_div != 0 && s.tick % o_.status_div == 0) {
    if (several_wheels()) send_side_wheels(s);
    send_status(s, false);
  }
}

void PoseBroadcaster::send_final(const loop::LoopSnapshot& s) noexcept {
  ack_ = static_cast<std::uint8_t>(ack_ + pending_ack_);
  pending_ack_ = 0;
  send_pose_group(s);
  if (several_wheels()) send_side_wheels(s);
  send_status(s, true);
}

void PoseBroadcaster::send_pose_group(const loop::LoopSnapshot& s) noexcept {
  if (sent_any_pose_) ++seq_;
  sent_any_pose_ = true;
  const protocol::PoseMsg p{s.pose.x, s.pose.y, s.pose.theta, seq_};
  CanFrame f;
  protocol::encode_pose_x(id(protocol::Msg::kPoseX), p, f);
  send(f);
  protocol::encode_pose_y_theta(id(protocol::Msg::kPoseYTheta), p, f);
  send(f);
}

void PoseBroadcaster::send_status(const loop::LoopSnapshot& s, bool stopping) noexcept {
  protocol::StatusMsg m;
  m.encoder_flags = static_cast<std::uint8_t>(s.encoder_flags & 0xFFu);
  m.calibration_state = static_cast<std::uint8_t>(s.calibration_state);
  m.stopping = stopping;
  m.set_pose_ack = ack_;
  m.missed_deadlines = static_cast<std::uint32_t>(s.stats.missed_deadlines);
  m.uptime = to_seconds(s.loop_time);
  CanFrame f;
  protocol::encode_status(id(protocol::Msg::kStatus), m, f);
  send(f);
}

void PoseBroadcaster::send_side_wheels(const loop::LoopSnapshot& s) noexcept {
  const auto n = static_cast<std::uint8_t>(o_.wheels_per_side);
  CanFrame f;
  protocol::encode_side_wheels(id(protocol::Msg::kSideWheels),
                               protocol::SideWheelsMsg{s.encoder_flags, n, s.encoder_counters}, f);
  send(f);
}

}  // namespace odo::board
