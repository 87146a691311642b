#include "odo/firmware/can_command_receiver.hpp"

namespace odo::fw {

void CanCommandReceiver::take_commands(TimeNs stamp) noexcept {
  rx_stamp_ = stamp;
  const CanFrame& f = rx_;
  for (std::size_t i = 0; i < o_.max_rx_per_tick; ++i) {
    if (i > 0 && !bus_->receive(rx_)) break;
    int node = 0;
    protocol::Msg m{};
    if (!protocol::split_id(o_.base_id, f, node, m) || node != o_.node_id) continue;
    if (m == protocol::Msg::kFixPose || m == protocol::Msg::kFixSigma) {
      if (fixes_ != nullptr) take_fix(f, m);
      continue;
    }
    if (m != protocol::Msg::kSetPose || !o_.set_pose)
      continue;  // not for us (a SocketCAN filter normally keeps these out)
    SetPose cmd;
    if (!protocol::decode_set_pose(f, cmd)) {
      ++c_->set_pose_rejected;
      continue;
    }
    if (commands_ != nullptr && !commands_->post(cmd)) {
      ++c_->set_pose_rejected;  // the loop's queue is full (it stopped taking commands)
      continue;
    }
    ++c_->set_pose_applied;
    ++pending_ack_;
  }
}

void CanCommandReceiver::take_fix(const CanFrame& f, protocol::Msg m) noexcept {
  if (m == protocol::Msg::kFixPose) {
    have_fix_half_ = protocol::decode_fix_pose(f, fix_half_);
    if (!have_fix_half_) ++c_->fixes_refused;
    return;
  }
  protocol::FixMsg fm = fix_half_;
  if (!have_fix_half_ || !protocol::decode_fix_sigma(f, fm) || fm.seq != fix_half_.seq) {
    ++c_->fixes_refused;
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
    ++c_->fixes_forwarded;
  else
    ++c_->fixes_refused;
}

}  // namespace odo::fw
