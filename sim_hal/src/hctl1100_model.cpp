#include "odo/sim/hctl1100_model.hpp"

namespace odo::sim {

void Hctl1100Model::sample(QuadState s) noexcept {
  const QuadStep step = quad_decode(state_, s);
  if (step == QuadStep::kInvalid) ++illegal_;
  counter_ = (counter_ + static_cast<std::uint32_t>(quad_delta(step))) & kMask;
  state_ = s;
}

void Hctl1100Model::follow(std::int64_t counts) noexcept {
  // One quadrature state per count: the decoder sees every edge in order.
  while (disc_ < counts) sample(quad_state_at(++disc_));
  while (disc_ > counts) sample(quad_state_at(--disc_));
}

std::int32_t Hctl1100Model::position() const noexcept {
  // Sign-extend bit 23 (two's complement).
  return static_cast<std::int32_t>(counter_ << 8) >> 8;
}

std::uint8_t Hctl1100Model::read_register(std::uint8_t reg) noexcept {
  std::uint32_t v = counter_;
  if (latch_ == Latch::kLsbLatch) {
    if (reg == kRegPosLsb) {
      latch_value_ = counter_;
      latched_ = true;
    } else if (latched_ && (reg == kRegPosMid || reg == kRegPosMsb)) {
      v = latch_value_;
      if (reg == kRegPosMsb) latched_ = false;
    }
  }
  switch (reg) {
    case kRegPosMsb:
      return static_cast<std::uint8_t>(v >> 16);
    case kRegPosMid:
      return static_cast<std::uint8_t>(v >> 8);
    case kRegPosLsb:
      return static_cast<std::uint8_t>(v);
    default:
      return 0;
  }
}

SimHctlBus::SimHctlBus(Hctl1100Model* unit0, Hctl1100Model* unit1) {
  units_[n_++] = unit0;
  if (unit1 != nullptr) units_[n_++] = unit1;
}

BusRead SimHctlBus::read_register(int unit, std::uint8_t reg) noexcept {
  if (hook_ != nullptr) hook_->on_bus_cycle();
  ++cycles_;
  if (fail_ > 0) {
    --fail_;
    return {};
  }
  if (unit < 0 || unit >= n_) return {};
  return {units_[unit]->read_register(reg), true};
}

}  // namespace odo::sim
