#include "odo/board/stm32_flash.hpp"

#include <string>

namespace odo::board {

namespace {
constexpr std::uint32_t kKey1 = 0x45670123, kKey2 = 0xCDEF89AB;
constexpr std::uint32_t kCrPg = 1u << 0, kCrSer = 1u << 1, kCrPsize32 = 2u << 8;
constexpr std::uint32_t kCrStrt = 1u << 16, kCrLock = 1u << 31;
constexpr std::uint32_t kSrEop = 1u << 0, kSrOperr = 1u << 1, kSrWrperr = 1u << 4;
constexpr std::uint32_t kSrPgaerr = 1u << 5, kSrPgperr = 1u << 6, kSrPgserr = 1u << 7;
constexpr std::uint32_t kSrBsy = 1u << 16;
constexpr std::uint32_t kSrErrors = kSrOperr | kSrWrperr | kSrPgaerr | kSrPgperr | kSrPgserr;
// A 128 KB sector erases in 1-2 s (data sheet); the poll is bounded so that a dead controller
// is an error, not a hang (the watchdog is not running while the store is written at start-up).
constexpr int kMaxPolls = 50000000;

Status flash_error(const char* what, std::uint32_t sr) {
  std::string m = std::string("flash ") + what + ":";
  if (sr & kSrPgserr) m += " programming sequence error (PGSERR)";
  if (sr & kSrPgperr) m += " parallelism error (PGPERR)";
  if (sr & kSrPgaerr) m += " alignment error (PGAERR)";
  if (sr & kSrWrperr) m += " write-protected (WRPERR)";
  if (sr & kSrOperr) m += " operation error (OPERR)";
  if (sr & kSrBsy) m += " still busy (no end of operation)";
  return make_error(Errc::kIo, m);
}
}  // namespace

std::uint32_t Stm32Flash::sector_size(int s) noexcept {
  return s < 4 ? 16u * 1024 : s == 4 ? 64u * 1024 : 128u * 1024;
}

std::uint32_t Stm32Flash::sector_base(int s) noexcept {
  std::uint32_t a = kFlashBase;
  for (int i = 0; i < s; ++i) a += sector_size(i);
  return a;
}

Status Stm32Flash::unlock() noexcept {
  if ((bus_->read(kCr) & kCrLock) != 0) {
    bus_->write(kKeyr, kKey1);
    bus_->write(kKeyr, kKey2);
  }
  // A wrong sequence locks the controller until reset: LOCK stays set.
  if ((bus_->read(kCr) & kCrLock) != 0) return make_error(Errc::kIo, "flash: unlock refused");
  bus_->write(kSr, kSrErrors | kSrEop);  // stale flags of an earlier operation (rc_w1)
  return Ok{};
}

void Stm32Flash::lock() noexcept {
  bus_->write(kCr, kCrLock);
}

Status Stm32Flash::finish(const char* what) noexcept {
  std::uint32_t sr = kSrBsy;
  for (int i = 0; i < kMaxPolls && (sr & kSrBsy) != 0; ++i) sr = bus_->read(kSr);
  if ((sr & (kSrErrors | kSrBsy)) != 0) {
    bus_->write(kSr, kSrErrors | kSrEop);
    return flash_error(what, sr);
  }
  bus_->write(kSr, kSrEop);
  return Ok{};
}

Status Stm32Flash::erase_sector(int s) noexcept {
  if (s < 0 || s >= kSectors) return make_error(Errc::kInvalidArgument, "flash: no such sector");
  if (auto u = unlock(); !u) return u;
  bus_->write(kCr, kCrSer | kCrPsize32 | (static_cast<std::uint32_t>(s) << 3));
  bus_->write(kCr, kCrSer | kCrPsize32 | (static_cast<std::uint32_t>(s) << 3) | kCrStrt);
  Status st = finish("sector erase");
  lock();
  return st;
}

Status Stm32Flash::program(std::uint32_t addr, std::span<const std::uint32_t> words) noexcept {
  if (addr % 4 != 0) return make_error(Errc::kInvalidArgument, "flash: unaligned program");
  if (auto u = unlock(); !u) return u;
  bus_->write(kCr, kCrPg | kCrPsize32);
  Status st = Ok{};
  for (std::size_t i = 0; i < words.size() && st; ++i) {
    bus_->write(addr + static_cast<std::uint32_t>(4 * i), words[i]);
    st = finish("program");
  }
  lock();
  return st;
}

NvGeometry FlashNvStorage::geometry() const noexcept {
  return NvGeometry{kWindow * static_cast<std::size_t>(count_), kWindow, 4};
}

Status FlashNvStorage::read(std::size_t off, std::span<std::uint8_t> out) {
  if (off + out.size() > geometry().size)
    return make_error(Errc::kInvalidArgument, "flash: read past the end");
  for (std::size_t i = 0; i < out.size(); ++i) {
    const std::size_t o = off + i;
    const std::uint32_t w = flash_->read_word(address(o & ~std::size_t{3}));
    out[i] = static_cast<std::uint8_t>(w >> (8 * (o & 3)));
  }
  return Ok{};
}

Status FlashNvStorage::write(std::size_t off, std::span<const std::uint8_t> data) {
  if (off % 4 != 0 || data.size() % 4 != 0 || off + data.size() > geometry().size)
    return make_error(Errc::kInvalidArgument, "flash: write not whole words inside the medium");
  for (std::size_t i = 0; i < data.size(); i += 4) {
    // Little-endian, as the chip reads its flash: byte k of the medium is byte k of the word.
    const std::uint32_t w = data[i] | (data[i + 1] << 8) | (data[i + 2] << 16) |
                            (static_cast<std::uint32_t>(data[i + 3]) << 24);
    if (auto s = flash_->program(address(off + i), std::span<const std::uint32_t>(&w, 1)); !s)
      return s;
  }
  return Ok{};
}

Status FlashNvStorage::erase(std::size_t off, std::size_t len) {
  if (off % kWindow != 0 || len % kWindow != 0 || off + len > geometry().size)
    return make_error(Errc::kInvalidArgument, "flash: erase not whole blocks inside the medium");
  for (std::size_t b = off / kWindow; b < (off + len) / kWindow; ++b) {
    if (auto st = flash_->erase_sector(first_ + static_cast<int>(b)); !st) return st;
  }
  return Ok{};
}

}  // namespace odo::board
