#include "odo/sim/stm32_timer_model.hpp"

#include <iterator>

namespace odo::sim {

Stm32TimerModel::Timer* Stm32TimerModel::timer(std::uint32_t addr, std::uint32_t& off) noexcept {
  off = addr & 0x3FFu;
  const std::uint32_t base = addr - off;
  if (base == kTim3) return &t_[0];
  if (base == kTim4) return &t_[1];
  if (base == kTim5) return &t_[2];
  if (base == kTim8) return &t_[3];
  return nullptr;
}

namespace {

// Offsets, model fields and the bits a write keeps (RM0090 18.4.1-18.4.12; TIM3 and TIM4 are
// 16-bit: CNT's and ARR's bits 31..16 read 0). TIM5 (32-bit) and TIM8 (advanced, 17.4) are
// modelled alike: the driver sets their range to 16 bits, and their further registers (TIM8's
// RCR, BDTR) are outputs' the encoder mode does not use.
struct Field {
  std::uint32_t off;
  std::uint32_t mask;
};
constexpr Field kFields[] = {{Stm32TimerModel::kCr1, 0x3FFu},    {Stm32TimerModel::kSmcr, 0xFFF7u},
                             {Stm32TimerModel::kCcmr1, 0xFFFFu}, {Stm32TimerModel::kCcer, 0xBBBBu},
                             {Stm32TimerModel::kCnt, 0xFFFFu},   {Stm32TimerModel::kPsc, 0xFFFFu},
                             {Stm32TimerModel::kArr, 0xFFFFu}};

}  // namespace

std::uint32_t* Stm32TimerModel::field(std::uint32_t addr, std::uint32_t& mask) noexcept {
  std::uint32_t off = 0;
  Timer* t = timer(addr, off);
  if (t == nullptr) return nullptr;
  for (std::size_t i = 0; i < std::size(kFields); ++i) {
    if (kFields[i].off == off) {
      mask = kFields[i].mask;
      return &t->regs[i];
    }
  }
  return nullptr;
}

std::uint32_t Stm32TimerModel::read(std::uint32_t addr) noexcept {
  std::uint32_t mask = 0;
  const std::uint32_t* f = field(addr, mask);
  return f != nullptr ? *f : 0;
}

void Stm32TimerModel::write(std::uint32_t addr, std::uint32_t v) noexcept {
  std::uint32_t mask = 0;
  if (std::uint32_t* f = field(addr, mask))
    *f = v & mask;
  else
    ++unknown_writes_;
}

bool Stm32TimerModel::counting(int unit) const noexcept {
  const Timer& t = t_[static_cast<std::size_t>(unit)];
  const bool enabled = (t.regs[kCr1i] & 1u) != 0;
  const std::uint32_t sms = t.regs[kSmcri] & 7u;
  const std::uint32_t ccmr1 = t.regs[kCcmr1i];
  const bool inputs = (ccmr1 & 3u) == 1u && ((ccmr1 >> 8) & 3u) == 1u;
  return enabled && sms >= 1 && sms <= 3 && inputs;
}

void Stm32TimerModel::edges(int unit, std::int64_t n) noexcept {
  if (!counting(unit)) return;
  Timer& t = t_[static_cast<std::size_t>(unit)];
  // Encoder mode 3 (SMS = 3) counts every edge of both channels; modes 1 and 2 only one channel's
  // (half the edges). The counter runs from 0 to ARR and wraps.
  const std::int64_t counts = (t.regs[kSmcri] & 7u) == 3u ? n : n / 2;
  const std::int64_t period = static_cast<std::int64_t>(t.regs[kArri]) + 1;
  std::int64_t c = (static_cast<std::int64_t>(t.regs[kCnti]) + counts) % period;
  if (c < 0) c += period;
  t.regs[kCnti] = static_cast<std::uint32_t>(c);
}

}  // namespace odo::sim
