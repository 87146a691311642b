#include "odo/sim/truth.hpp"

#include <cmath>

namespace odo::sim {

double TruthSample::position_error() const noexcept {
  return std::hypot(pose.x - truth.x, pose.y - truth.y);
}

void TruthRecorder::on_tick(const loop::LoopSnapshot& snap) noexcept {
  TruthSample& s = samples_.back();
  s.tick = snap.tick;
  s.truth = robot_.true_pose();
  s.pose = snap.pose;
  samples_.publish();
}

EncoderSample EpochEncoder::read(TimeNs now) noexcept {
  if (!started_) {
    epoch_ = now;
    started_ = true;
  }
  EncoderSample s = inner_.read(now - epoch_);
  s.stamp = now;
  return s;
}

}  // namespace odo::sim
