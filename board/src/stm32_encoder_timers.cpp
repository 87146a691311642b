#include "odo/board/stm32_encoder_timers.hpp"

#include "odo/hal/side_sample.hpp"

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

void init_encoder_timer(RegisterBus& bus, std::uint32_t base) noexcept {
  bus.write(base + kCr1, 0);  // stopped while configured
  bus.write(base + kCcmr1, kCcmr1Inputs);
  bus.write(base + kCcer, 0);  // both inputs non-inverted (a mirrored motor: swap A and B)
  bus.write(base + kSmcr, kSmsEncoder3);
  // 16 bits also on TIM5 (a 32-bit timer): every wheel of a side wraps alike.
  bus.write(base + kArr, 0xFFFF);
  bus.write(base + kCnt, 0);
  bus.write(base + kCr1, kCr1Cen);
}

std::int64_t read_encoder_timer(RegisterBus& bus, std::uint32_t base) noexcept {
  return static_cast<std::int64_t>(bus.read(base + kCnt) & 0xFFFFu);
}

void Stm32EncoderTimers::init() noexcept {
  init_encoder_timer(*bus_, kTim3);
  init_encoder_timer(*bus_, kTim4);
}

EncoderSample Stm32EncoderTimers::read(TimeNs now) noexcept {
  EncoderSample s;
  s.left = read_encoder_timer(*bus_, kTim3);
  s.right = read_encoder_timer(*bus_, kTim4);
  s.stamp = now;
  return s;
}

std::optional<Stm32SideTimers> Stm32SideTimers::create(RegisterBus& bus,
                                                       SideWheelsConfig c) noexcept {
  c.wheels_per_side = 2;
  c.counter_bits = 16;
  auto combiner = SideCombiner::make(c);
  if (!combiner) return std::nullopt;
  return Stm32SideTimers(bus, *combiner);
}

void Stm32SideTimers::init() noexcept {
  for (std::size_t i = 0; i < kLeft.size(); ++i) {
    init_encoder_timer(*bus_, kLeft[i]);
    init_encoder_timer(*bus_, kRight[i]);
  }
}

EncoderSample Stm32SideTimers::read(TimeNs now) noexcept {
  // A timer's counter cannot fault (no decoder error is reported): faulted stays 0.
  for (std::size_t i = 0; i < kLeft.size(); ++i) {
    readings_[0].counts[i] = read_encoder_timer(*bus_, kLeft[i]);
    readings_[1].counts[i] = read_encoder_timer(*bus_, kRight[i]);
  }
  const SideStep step = combiner_.step(readings_[0], readings_[1]);
  EncoderSample s;
  s.stamp = now;
  apply_side_step(step, combiner_.counters(), s);
  return s;
}

}  // namespace odo::board
