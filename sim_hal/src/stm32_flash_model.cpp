#include "odo/sim/stm32_flash_model.hpp"

namespace odo::sim {

namespace {
constexpr std::uint32_t kKey1 = 0x45670123, kKey2 = 0xCDEF89AB;
constexpr std::uint32_t kCrPg = 1u << 0, kCrSer = 1u << 1, kCrStrt = 1u << 16;
constexpr std::uint32_t kCrLock = 1u << 31;
constexpr std::uint32_t kSrEop = 1u << 0, kSrOperr = 1u << 1, kSrWrperr = 1u << 4, kSrPgaerr = 1u << 5;
constexpr std::uint32_t kSrPgperr = 1u << 6, kSrPgserr = 1u << 7;
}  // namespace

Stm32FlashModel::Stm32FlashModel(std::uint32_t base, std::size_t sector_size, int first, int count)
    : base_(base),
      sector_size_(sector_size),
      first_(first),
      count_(count),
      mem_(sector_size * static_cast<std::size_t>(count), 0xFF) {}

void Stm32FlashModel::power_on() noexcept {
  powered_ = true;
  budget_ = UINT64_MAX;
  cr_ = kCrLock;
  sr_ = 0;
  keys_ = 0;
}

bool Stm32FlashModel::step() noexcept {
  if (budget_ == 0) {
    powered_ = false;
    return false;
  }
  --budget_;
  ++steps_;
  return true;
}

std::uint32_t Stm32FlashModel::read(std::uint32_t addr) noexcept {
  // Without power the chip's code would not run on either; on the host the driver goes on, and
  // the status says the operation failed (OPERR), so it returns at once with an error.
  if (addr == kSr) return powered_ ? sr_ : kSrOperr;
  if (addr == kCr) return cr_;
  if (addr >= base_ && addr - base_ + 4 <= mem_.size() && addr % 4 == 0) {
    const std::size_t o = addr - base_;
    return mem_[o] | (mem_[o + 1] << 8) | (mem_[o + 2] << 16) |
           (static_cast<std::uint32_t>(mem_[o + 3]) << 24);
  }
  return 0;
}

void Stm32FlashModel::write(std::uint32_t addr, std::uint32_t v) noexcept {
  if (!powered_) return;
  if (addr == kKeyr) {
    // KEY1 then KEY2 unlocks; anything else locks CR until the next reset (power_on).
    if (keys_ == 0 && v == kKey1) {
      keys_ = 1;
    } else if (keys_ == 1 && v == kKey2) {
      keys_ = 0;
      cr_ &= ~kCrLock;
    } else {
      keys_ = 2;
    }
  } else if (addr == kSr) {
    sr_ &= ~(v & 0xF3u);  // rc_w1 flags
  } else if (addr == kCr) {
    write_cr(v);
  } else if (addr >= base_ && addr - base_ < mem_.size()) {
    program_word(addr, v);
  }
}

void Stm32FlashModel::write_cr(std::uint32_t v) noexcept {
  if ((cr_ & kCrLock) != 0) return;  // locked: CR cannot be written
  cr_ = v;
  if ((v & kCrStrt) == 0 || (v & kCrSer) == 0) return;
  const int snb = static_cast<int>((v >> 3) & 0xFu);
  if (snb < first_ || snb >= first_ + count_) {
    sr_ |= kSrWrperr;  // a sector the model does not hold: as if protected
    return;
  }
  auto* p = mem_.data() + static_cast<std::size_t>(snb - first_) * sector_size_;
  if (!step()) {
    if (tear_)
      for (std::size_t i = 0; i < sector_size_; ++i) p[i] = static_cast<std::uint8_t>(rng_());
    return;
  }
  for (std::size_t i = 0; i < sector_size_; ++i) p[i] = 0xFF;
  sr_ |= kSrEop;
  cr_ &= ~kCrStrt;
}

void Stm32FlashModel::program_word(std::uint32_t addr, std::uint32_t v) noexcept {
  if ((cr_ & kCrPg) == 0 || (cr_ & kCrLock) != 0) {
    sr_ |= kSrPgserr;  // a write into flash without PG
    return;
  }
  if (((cr_ >> 8) & 3u) != 2u) {
    sr_ |= kSrPgperr;  // the model takes only 32-bit parallelism (PSIZE x32)
    return;
  }
  if (addr % 4 != 0) {
    sr_ |= kSrPgaerr;
    return;
  }
  const std::size_t o = addr - base_;
  std::uint32_t target = v;
  if (!step()) {
    if (!tear_) return;
    // A word cut while programming: some of its 1 -> 0 transitions happened.
    target = v | static_cast<std::uint32_t>(rng_());
  }
  for (int k = 0; k < 4; ++k) mem_[o + k] &= static_cast<std::uint8_t>(target >> (8 * k));
  if (powered_) sr_ |= kSrEop;
}

}  // namespace odo::sim
