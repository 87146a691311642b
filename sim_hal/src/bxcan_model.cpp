#include "odo/sim/bxcan_model.hpp"

namespace odo::sim {

namespace {
constexpr std::uint32_t kMcr = 0x00, kMsr = 0x04, kTsr = 0x08, kRf0r = 0x0C, kBtr = 0x1C;
constexpr std::uint32_t kTx = 0x180, kRx0 = 0x1B0, kFmr = 0x200, kFm1r = 0x204, kFs1r = 0x20C;
constexpr std::uint32_t kFfa1r = 0x214, kFa1r = 0x21C, kBanks = 0x240;

// frame_of: a CanFrame from the mailbox words (identifier, DLC, data low, data high).
CanFrame frame_of(const std::array<std::uint32_t, 4>& m) {
  CanFrame f;
  f.extended = (m[0] & 4u) != 0;
  f.rtr = (m[0] & 2u) != 0;
  f.id = f.extended ? m[0] >> 3 : m[0] >> 21;
  f.len = static_cast<std::uint8_t>(m[1] & 0xFu);
  for (int i = 0; i < 4; ++i) {
    f.data[static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(m[2] >> (8 * i));
    f.data[static_cast<std::size_t>(i + 4)] = static_cast<std::uint8_t>(m[3] >> (8 * i));
  }
  return f;
}
}  // namespace

std::uint32_t BxCanModel::read(std::uint32_t addr) noexcept {
  const std::uint32_t off = addr - kBase;
  if (off == kMcr) return mcr_;
  if (off == kMsr) return msr_;
  if (off == kBtr) return btr_;
  if (off == kRf0r) return rf0r_ | static_cast<std::uint32_t>(fifo0_.size());
  if (off == kTsr) {
    std::uint32_t tsr = 0;
    for (int i = 0; i < 3; ++i) {
      if ((tx_[static_cast<std::size_t>(i)][0] & 1u) == 0) tsr |= 1u << (26 + i);  // TMEi
    }
    return tsr;
  }
  if (off >= kTx && off < kTx + 0x30) return tx_[(off - kTx) / 0x10][(off - kTx) % 0x10 / 4];
  if (off >= kRx0 && off < kRx0 + 0x10)
    return fifo0_.empty() ? 0 : fifo0_.front()[(off - kRx0) / 4];
  if (off == kFmr) return fmr_;
  if (off == kFm1r) return fm1r_;
  if (off == kFs1r) return fs1r_;
  if (off == kFfa1r) return ffa1r_;
  if (off == kFa1r) return fa1r_;
  if (off >= kBanks && off < kBanks + 14 * 8)
    return banks_[(off - kBanks) / 8][(off - kBanks) % 8 / 4];
  return 0;
}

void BxCanModel::write(std::uint32_t addr, std::uint32_t v) noexcept {
  const std::uint32_t off = addr - kBase;
  const bool finit = (fmr_ & 1u) != 0;
  if (off == kMcr) {
    mcr_ = v;
    // INRQ: initialisation (INAK set), else normal mode; SLEEP clears with INRQ as on the chip.
    msr_ = (v & 1u) != 0 ? (msr_ | 1u) & ~2u : msr_ & ~3u;
  } else if (off == kBtr) {
    if (initialising()) btr_ = v;  // BTR is writable only in initialisation mode
  } else if (off == kRf0r) {
    if ((v & (1u << 5)) != 0 && !fifo0_.empty()) fifo0_.pop_front();  // RFOM0
    rf0r_ &= ~(v & ((1u << 3) | (1u << 4)));                          // FULL0, FOVR0: rc_w1
  } else if (off >= kTx && off < kTx + 0x30) {
    tx_[(off - kTx) / 0x10][(off - kTx) % 0x10 / 4] = v;
  } else if (off == kFmr) {
    fmr_ = (fmr_ & ~1u) | (v & 1u);
  } else if (off == kFa1r) {
    fa1r_ = v & 0x3FFFu;
  } else if (finit && off == kFm1r) {
    fm1r_ = v & 0x3FFFu;  // mode, scale and assignment change only with FINIT
  } else if (finit && off == kFs1r) {
    fs1r_ = v & 0x3FFFu;
  } else if (finit && off == kFfa1r) {
    ffa1r_ = v & 0x3FFFu;
  } else if (off >= kBanks && off < kBanks + 14 * 8) {
    const std::uint32_t b = (off - kBanks) / 8;
    // A bank's registers are written while it is inactive or in filter initialisation.
    if (finit || (fa1r_ & (1u << b)) == 0) banks_[b][(off - kBanks) % 8 / 4] = v;
  }
}

void BxCanModel::transmit() noexcept {
  if (initialising()) return;
  for (auto& m : tx_) {
    if ((m[0] & 1u) == 0) continue;
    sent_.push_back(frame_of(m));
    m[0] &= ~1u;
  }
}

int BxCanModel::match(std::uint32_t ir) const noexcept {
  for (int b = 0; b < 14; ++b) {
    const auto bit = 1u << b;
    if ((fa1r_ & bit) == 0 || (fs1r_ & bit) == 0) continue;  // inactive, or 16-bit scale
    const auto& r = banks_[static_cast<std::size_t>(b)];
    const bool list = (fm1r_ & bit) != 0;
    const bool hit = list ? (ir == r[0] || ir == r[1]) : ((ir ^ r[0]) & r[1] & ~1u) == 0;
    if (hit) return b;
  }
  return -1;
}

bool BxCanModel::deliver(const CanFrame& f) noexcept {
  if (initialising()) return false;
  std::array<std::uint32_t, 4> m{};
  m[0] = (f.extended ? (f.id << 3) | 4u : f.id << 21) | (f.rtr ? 2u : 0u);
  m[1] = f.len;
  for (int i = 0; i < 4; ++i) {
    m[2] |= static_cast<std::uint32_t>(f.data[static_cast<std::size_t>(i)]) << (8 * i);
    m[3] |= static_cast<std::uint32_t>(f.data[static_cast<std::size_t>(i + 4)]) << (8 * i);
  }
  const int b = match(m[0]);
  if (b < 0) return false;
  if ((ffa1r_ & (1u << b)) != 0) {
    ++fifo1_;
    return false;
  }
  if (fifo0_.size() == 3) {
    rf0r_ |= 1u << 4;  // FOVR0
    // MCR.RFLM (bit 3) set: the new frame is lost; clear (the reset value): it replaces the
    // newest frame in the FIFO.
    if ((mcr_ & 8u) != 0) return false;
    fifo0_.back() = m;
    return true;
  }
  fifo0_.push_back(m);
  if (fifo0_.size() == 3) rf0r_ |= 1u << 3;  // FULL0
  return true;
}

}  // namespace odo::sim
