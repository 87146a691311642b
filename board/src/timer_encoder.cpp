#include "odo/board/timer_encoder.hpp"

#include "odo/board/stm32f4.hpp"

namespace odo::board {

namespace {
constexpr std::uintptr_t kTim3 = 0x40000400, kTim4 = 0x40000800;
constexpr std::uintptr_t kSmcr = 0x08, kCcmr1 = 0x18, kCcer = 0x20;

void encoder_mode(std::uintptr_t t) noexcept {
  reg(t + tim::kCr1) = 0;
  reg(t + kCcmr1) = (1u << 0) | (1u << 8);  // CC1S = TI1, CC2S = TI2
  reg(t + kCcer) = 0;                       // both inputs non-inverted
  reg(t + kSmcr) = 3u;                      // SMS = encoder mode 3
  reg(t + tim::kArr) = 0xFFFF;
  reg(t + tim::kCnt) = 0;
  reg(t + tim::kCr1) = tim::kCr1Cen;
}
}  // namespace

void TimerEncoder::init() noexcept {
  reg(rcc::kApb1Enr) |= (1u << 1) | (1u << 2);  // TIM3, TIM4
  encoder_mode(kTim3);
  encoder_mode(kTim4);
}

EncoderSample TimerEncoder::read(TimeNs now) noexcept {
  EncoderSample s;
  s.left = static_cast<std::int64_t>(reg(kTim3 + tim::kCnt) & 0xFFFFu);
  s.right = static_cast<std::int64_t>(reg(kTim4 + tim::kCnt) & 0xFFFFu);
  s.stamp = now;
  return s;
}

}  // namespace odo::board
