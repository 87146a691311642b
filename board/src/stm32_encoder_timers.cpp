#include "odo/board/stm32_encoder_timers.hpp"

namespace odo::board {

namespace {
// RM0090 18.4: register offsets and the bits the driver sets.
constexpr std::uint32_t kCr1 = 0x00, kSmcr = 0x08, kCcmr1 = 0x18, kCcer = 0x20, kCnt = 0x24;
constexpr std::uint32_t kArr = 0x2C;
constexpr std::uint32_t kCr1Cen = 1u << 0;
constexpr std::uint32_t kSmsEncoder3 = 3u;  // counts on TI1 and TI2 edges
// CC1S = 01 (IC1 on TI1), CC2S = 01 (IC2 on TI2), IC1F = IC2F = 0011 (fCK_INT, N = 8): a glitch
// shorter than 8 timer clocks is no edge.
constexpr std::uint32_t kCcmr1Inputs = (1u << 0) | (3u << 4) | (1u << 8) | (3u << 12);
}  // namespace

void Stm32EncoderTimers::init_timer(std::uint32_t base) noexcept {
  bus_->write(base + kCr1, 0);  // stopped while configured
  bus_->write(base + kCcmr1, kCcmr1Inputs);
  bus_->write(base + kCcer, 0);  // both inputs non-inverted (a mirrored motor: swap A and B)
  bus_->write(base + kSmcr, kSmsEncoder3);
  bus_->write(base + kArr, 0xFFFF);
  bus_->write(base + kCnt, 0);
  bus_->write(base + kCr1, kCr1Cen);
}

void Stm32EncoderTimers::init() noexcept {
  init_timer(kTim3);
  init_timer(kTim4);
}

EncoderSample Stm32EncoderTimers::read(TimeNs now) noexcept {
  EncoderSample s;
  s.left = static_cast<std::int64_t>(bus_->read(kTim3 + kCnt) & 0xFFFFu);
  s.right = static_cast<std::int64_t>(bus_->read(kTim4 + kCnt) & 0xFFFFu);
  s.stamp = now;
  return s;
}

}  // namespace odo::board
