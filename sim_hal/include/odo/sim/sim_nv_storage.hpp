// SimNvStorage: a simulated non-volatile medium with fault injection. Models an EEPROM (bytes
// overwritten in place) or a NOR flash (erase sets a block to 0xFF, programming can only clear
// bits). Every programmed or erased byte is one step; the power can be cut after any step, the
// page in flight can be torn (left with random bits), and stored bits can be flipped.
#pragma once

#include <cstdint>
#include <random>
#include <vector>

#include "odo/hal/nv_storage.hpp"

namespace odo::sim {

enum class SimMedium : std::uint8_t { kEeprom, kFlash };

class SimNvStorage final : public NvStorage {
 public:
  // size: bytes; erase_block: flash erase block (ignored for kEeprom); page: the unit that a
  // cut tears (EEPROM page / flash program page), >= 1. The medium starts erased (all 0xFF).
  SimNvStorage(SimMedium kind, std::size_t size, std::size_t erase_block, std::size_t page);

  NvGeometry geometry() const noexcept override;
  Status read(std::size_t off, std::span<std::uint8_t> out) override;
  Status write(std::size_t off, std::span<const std::uint8_t> data) override;
  Status erase(std::size_t off, std::size_t len) override;

  // cut_power_after: the next `steps` byte steps succeed, then the power fails: the operation in
  // flight stops and every later one fails with Errc::kIo until power_on().
  void cut_power_after(std::uint64_t steps) noexcept { budget_ = steps; }
  // set_tear: when the power fails, the rest of the page in flight gets random bits (seeded).
  void set_tear(bool on, std::uint64_t seed) noexcept {
    tear_ = on;
    rng_.seed(seed);
  }
  // power_on: restores power (a reboot) and removes any pending cut.
  void power_on() noexcept {
    powered_ = true;
    budget_ = kNoCut;
  }
  bool powered() const noexcept { return powered_; }
  // flip_bit: inverts one stored bit (radiation, retention loss, a worn cell).
  void flip_bit(std::size_t byte, int bit) noexcept {
    bytes_[byte] ^= static_cast<std::uint8_t>(1U << bit);
  }
  // steps: byte steps performed since construction (to size exhaustive power-cut sweeps).
  std::uint64_t steps() const noexcept { return steps_; }
  const std::vector<std::uint8_t>& raw() const noexcept { return bytes_; }
  std::vector<std::uint8_t>& raw() noexcept { return bytes_; }

 private:
  static constexpr std::uint64_t kNoCut = ~std::uint64_t{0};
  // step: consumes one step of the budget; false (and the power is off) when it ran out.
  bool step() noexcept;
  void tear_from(std::size_t pos, bool erasing);

  SimMedium kind_;
  std::size_t erase_block_;
  std::size_t page_;
  std::vector<std::uint8_t> bytes_;
  bool powered_ = true;
  std::uint64_t budget_ = kNoCut;
  std::uint64_t steps_ = 0;
  bool tear_ = false;
  std::mt19937_64 rng_;
};

}  // namespace odo::sim
