#include "odo/board/bxcan.hpp"

namespace odo::board {

namespace {
constexpr std::uint32_t kMcr = 0x00, kMsr = 0x04, kTsr = 0x08, kRf0r = 0x0C, kBtr = 0x1C;
constexpr std::uint32_t kTi0r = 0x180, kRi0r = 0x1B0;  // mailbox i at + 0x10 * i
constexpr std::uint32_t kFmr = 0x200, kFm1r = 0x204, kFs1r = 0x20C, kFfa1r = 0x214;
constexpr std::uint32_t kFa1r = 0x21C, kF0r1 = 0x240, kF0r2 = 0x244;
constexpr std::uint32_t kMcrInrq = 1u << 0, kMcrAbom = 1u << 6;
constexpr std::uint32_t kMsrInak = 1u << 0;
constexpr std::uint32_t kTsrTme0 = 1u << 26;  // TME0..2: bits 26..28
constexpr std::uint32_t kTirTxrq = 1u << 0, kIrRtr = 1u << 1, kIrIde = 1u << 2;
constexpr std::uint32_t kRf0rFmp = 3u, kRf0rRfom = 1u << 5;
constexpr int kMaxPolls = 100000;

std::uint32_t reg_of(std::uint32_t off) {
  return BxCan::kBase + off;
}
}  // namespace

Status BxCan::wait_inak(bool set) noexcept {
  for (int i = 0; i < kMaxPolls; ++i) {
    if (((bus_->read(reg_of(kMsr)) & kMsrInak) != 0) == set) return Ok{};
  }
  return make_error(Errc::kIo, set ? "bxCAN: no initialisation mode (INAK stays 0)"
                                   : "bxCAN: does not leave initialisation (no 11 recessive bits)");
}

Status BxCan::init(std::uint32_t btr, std::uint32_t accept, std::uint32_t mask) noexcept {
  bus_->write(reg_of(kMcr), kMcrInrq);  // out of sleep, into initialisation
  if (auto s = wait_inak(true); !s) return s;
  bus_->write(reg_of(kBtr), btr);
  // Filters: bank 0, 32-bit identifier-mask, FIFO 0 (STID in bits 31..21 of both registers).
  bus_->write(reg_of(kFmr), 1u);  // FINIT
  bus_->write(reg_of(kFa1r), 0);
  bus_->write(reg_of(kFm1r), 0);
  bus_->write(reg_of(kFs1r), 1u);
  bus_->write(reg_of(kFfa1r), 0);
  bus_->write(reg_of(kF0r1), (accept & 0x7FFu) << 21);
  bus_->write(reg_of(kF0r2), ((mask & 0x7FFu) << 21) | kIrIde | kIrRtr);  // data frames, 11-bit
  bus_->write(reg_of(kFa1r), 1u);
  bus_->write(reg_of(kFmr), 0);
  bus_->write(reg_of(kMcr), kMcrAbom);  // normal mode, automatic bus-off recovery
  return wait_inak(false);
}

CanTx BxCan::send(const CanFrame& f) noexcept {
  const std::uint32_t tsr = bus_->read(reg_of(kTsr));
  int box = -1;
  for (int i = 0; i < 3 && box < 0; ++i) {
    if ((tsr & (kTsrTme0 << i)) != 0) box = i;
  }
  if (box < 0) return CanTx::kQueueFull;
  const std::uint32_t mb = kTi0r + 0x10u * static_cast<std::uint32_t>(box);
  const std::uint8_t len = f.len > 8 ? 8 : f.len;
  std::uint32_t lo = 0, hi = 0;
  for (int i = 0; i < 4; ++i) {
    lo |= static_cast<std::uint32_t>(f.data[static_cast<std::size_t>(i)]) << (8 * i);
    hi |= static_cast<std::uint32_t>(f.data[static_cast<std::size_t>(i + 4)]) << (8 * i);
  }
  bus_->write(reg_of(mb + 4), len);
  bus_->write(reg_of(mb + 8), lo);
  bus_->write(reg_of(mb + 12), hi);
  const std::uint32_t id =
      f.extended ? ((f.id & 0x1FFFFFFFu) << 3) | kIrIde : (f.id & 0x7FFu) << 21;
  bus_->write(reg_of(mb), id | (f.rtr ? kIrRtr : 0u) | kTirTxrq);
  return CanTx::kSent;
}

bool BxCan::receive(CanFrame& out) noexcept {
  if ((bus_->read(reg_of(kRf0r)) & kRf0rFmp) == 0) return false;
  const std::uint32_t ir = bus_->read(reg_of(kRi0r));
  const std::uint32_t dt = bus_->read(reg_of(kRi0r + 4));
  const std::uint32_t lo = bus_->read(reg_of(kRi0r + 8));
  const std::uint32_t hi = bus_->read(reg_of(kRi0r + 12));
  bus_->write(reg_of(kRf0r), kRf0rRfom);  // release the FIFO's output mailbox
  CanFrame f;
  f.extended = (ir & kIrIde) != 0;
  f.rtr = (ir & kIrRtr) != 0;
  f.id = f.extended ? ir >> 3 : ir >> 21;
  f.len = static_cast<std::uint8_t>((dt & 0xFu) > 8 ? 8 : dt & 0xFu);
  for (int i = 0; i < 4; ++i) {
    f.data[static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(lo >> (8 * i));
    f.data[static_cast<std::size_t>(i + 4)] = static_cast<std::uint8_t>(hi >> (8 * i));
  }
  out = f;
  return true;
}

}  // namespace odo::board
