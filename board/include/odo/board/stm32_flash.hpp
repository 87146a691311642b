// Stm32Flash: the STM32F4's flash interface at register level (RM0090 3.5-3.9): unlock with the
// key sequence, sector erase, 32-bit word programming, lock, and the error flags (PGSERR, PGPERR,
// PGAERR, WRPERR, OPERR) turned into errors. FlashNvStorage puts the calibration store's
// NvStorage on two of its sectors (erase a sector, program words: bits only go from 1 to 0).
// Register and flash access through a RegisterBus: MmioBus on the chip, sim::Stm32FlashModel
// (with power cuts at every word) on the host.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>

#include "odo/hal/nv_storage.hpp"
#include "odo/hal/register_bus.hpp"

namespace odo::board {

class Stm32Flash {
 public:
  static constexpr std::uint32_t kFlashBase = 0x08000000;
  static constexpr std::uint32_t kKeyr = 0x40023C04, kSr = 0x40023C0C, kCr = 0x40023C10;
  static constexpr int kSectors = 12;  // 1 MB parts: 4 x 16 KB, 64 KB, 7 x 128 KB

  explicit Stm32Flash(RegisterBus& bus) noexcept : bus_(&bus) {}
  // sector_base, sector_size: where sector `s` (0..11) starts [address] and its size [bytes].
  static std::uint32_t sector_base(int s) noexcept;
  static std::uint32_t sector_size(int s) noexcept;
  // erase_sector: sector `s` to all ones. Errors: a bad sector, the controller's error flags, or
  // no end of operation within the bounded wait (a chip that lost power).
  Status erase_sector(int s) noexcept;
  // program: `words` from the word-aligned address `addr` (each word only clears bits).
  Status program(std::uint32_t addr, std::span<const std::uint32_t> words) noexcept;
  // read_word: the word at the word-aligned address `addr`.
  std::uint32_t read_word(std::uint32_t addr) noexcept { return bus_->read(addr); }

 private:
  Status unlock() noexcept;
  // finish: waits for BSY to clear, turns error flags into an error naming `what`, clears them.
  Status finish(const char* what) noexcept;
  void lock() noexcept;
  RegisterBus* bus_;
};

// FlashNvStorage: sectors [first, first + count) as an NvStorage of `count` erase blocks of
// `window` bytes each: block i is the first `window` bytes of sector first + i (erasing the
// block erases the whole sector; the rest of the sector is never used). Write unit: a word. The
// calibration store's A/B slots then each take a sector, and a slot is `window` bytes (the store
// reads a slot whole: 128 KB sectors would not fit in RAM).
class FlashNvStorage final : public NvStorage {
 public:
  static constexpr std::size_t kWindow = 512;  // >= the largest record (148 bytes)
  FlashNvStorage(Stm32Flash& flash, int first, int count) noexcept
      : flash_(&flash), first_(first), count_(count) {}
  NvGeometry geometry() const noexcept override;
  Status read(std::size_t off, std::span<std::uint8_t> out) override;
  Status write(std::size_t off, std::span<const std::uint8_t> data) override;
  Status erase(std::size_t off, std::size_t len) override;

 private:
  // address: the flash address of medium offset `off`.
  std::uint32_t address(std::size_t off) const noexcept {
    return Stm32Flash::sector_base(first_ + static_cast<int>(off / kWindow)) +
           static_cast<std::uint32_t>(off % kWindow);
  }
  Stm32Flash* flash_;
  int first_;
  int count_;
};

}  // namespace odo::board
