#include "odo/sim/sim_can_bus.hpp"

#include <algorithm>

namespace odo::sim {

bool FrameRing::push(const CanFrame& f) noexcept {
  if (size_ == buf_.size()) return false;
  buf_[(head_ + size_) % buf_.size()] = f;
  ++size_;
  return true;
}

bool FrameRing::pop(CanFrame& out) noexcept {
  if (size_ == 0) return false;
  out = buf_[head_];
  head_ = (head_ + 1) % buf_.size();
  --size_;
  return true;
}

SimCanPort::SimCanPort(std::size_t tx_capacity, std::size_t rx_capacity)
    : tx_(std::max<std::size_t>(tx_capacity, 1)), rx_(std::max<std::size_t>(rx_capacity, 1)) {}

CanTx SimCanPort::send(const CanFrame& f) noexcept {
  if (!up_) {
    ++counters_.tx_down;
    return CanTx::kLinkDown;
  }
  if (!wire_ && !tx_.push(f)) {
    ++counters_.tx_full;
    return CanTx::kQueueFull;
  }
  ++counters_.sent;
  return CanTx::kSent;
}

bool SimCanPort::receive(CanFrame& out) noexcept {
  return rx_.pop(out);
}

bool SimCanPort::inject(const CanFrame& f) noexcept {
  // A downed link receives nothing; a full socket buffer drops the newest frame (as the kernel).
  if (!up_ || !rx_.push(f)) {
    ++counters_.rx_dropped;
    return false;
  }
  return true;
}

void SimCanPort::set_link_up(bool up) noexcept {
  if (!up) tx_.clear();
  up_ = up;
}

}  // namespace odo::sim
