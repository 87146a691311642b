// Stm32FlashModel: register model of the STM32F4 flash interface (RM0090 3.5-3.9) with the memory
// of `count` equal sectors from sector `first` at `base`, for the board's flash driver on the host
// (issue 36). KEYR (the two-key unlock; a wrong key locks until reset), CR (PG, SER, SNB, PSIZE,
// STRT, LOCK), SR (EOP, OPERR, WRPERR, PGAERR, PGPERR, PGSERR, BSY; rc_w1). A sector erase sets
// its bytes to 0xFF; programming a word ANDs it in (bits only go from 1 to 0). Faults: the power
// can be cut after any step (one step: a sector erase, or one programmed word); the operation in
// flight is then lost, or with tearing leaves random bits (an erase: the whole sector; a program:
// a random part of the word's 1->0 bits); afterwards SR reads OPERR (the chip's code would have
// died with it; the driver on the host returns an error at once) until power_on(). Stored bits
// can be flipped.
#pragma once

#include <cstddef>
#include <cstdint>
#include <random>
#include <vector>

#include "odo/hal/register_bus.hpp"

namespace odo::sim {

class Stm32FlashModel final : public RegisterBus {
 public:
  static constexpr std::uint32_t kKeyr = 0x40023C04, kSr = 0x40023C0C, kCr = 0x40023C10;

  // Stm32FlashModel: sectors first..first+count-1 of sector_size bytes from address `base`.
  Stm32FlashModel(std::uint32_t base, std::size_t sector_size, int first, int count);
  std::uint32_t read(std::uint32_t addr) noexcept override;
  void write(std::uint32_t addr, std::uint32_t value) noexcept override;

  void cut_power_after(std::uint64_t steps) noexcept { budget_ = steps; }
  void set_tear(bool on, std::uint64_t seed) noexcept {
    tear_ = on;
    rng_.seed(seed);
  }
  // power_on: a reboot: power back, the controller locked, flags clear, no cut pending.
  void power_on() noexcept;
  bool powered() const noexcept { return powered_; }
  // flip_bit: inverts bit `bit` of byte `byte` of the modelled memory.
  void flip_bit(std::size_t byte, int bit) noexcept {
    mem_[byte] ^= static_cast<std::uint8_t>(1u << bit);
  }
  std::uint64_t steps() const noexcept { return steps_; }
  const std::vector<std::uint8_t>& raw() const noexcept { return mem_; }

 private:
  // step: one step of the budget; false when the power failed on it.
  bool step() noexcept;
  void write_cr(std::uint32_t v) noexcept;
  void program_word(std::uint32_t addr, std::uint32_t v) noexcept;
  std::uint32_t base_;
  std::size_t sector_size_;
  int first_, count_;
  std::vector<std::uint8_t> mem_;
  std::uint32_t cr_ = 0x80000000u, sr_ = 0;
  int keys_ = 0;  // key sequence position
  bool powered_ = true, tear_ = false;
  std::uint64_t budget_ = UINT64_MAX, steps_ = 0;
  std::mt19937_64 rng_;
};

}  // namespace odo::sim
