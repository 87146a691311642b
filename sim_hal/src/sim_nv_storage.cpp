#include "odo/sim/sim_nv_storage.hpp"

#include <algorithm>
#include <string>

namespace odo::sim {
namespace {

Error power_lost() {
  return make_error(Errc::kIo, "simulated power loss");
}

}  // namespace

SimNvStorage::SimNvStorage(SimMedium kind, std::size_t size, std::size_t erase_block,
                           std::size_t page)
    : kind_(kind),
      erase_block_(kind == SimMedium::kFlash ? erase_block : 0),
      page_(std::max<std::size_t>(page, 1)),
      bytes_(size, 0xFF) {}

NvGeometry SimNvStorage::geometry() const noexcept {
  return NvGeometry{bytes_.size(), erase_block_, 1};
}

bool SimNvStorage::step() noexcept {
  if (budget_ == 0) {
    powered_ = false;
    return false;
  }
  if (budget_ != kNoCut) --budget_;
  ++steps_;
  return true;
}

void SimNvStorage::tear_from(std::size_t pos, bool erasing) {
  if (!tear_) return;
  // The cells of the page (erase: the block) in flight end up anywhere between old and new.
  const std::size_t unit = (erasing && erase_block_ > 0) ? erase_block_ : page_;
  const std::size_t end = std::min(bytes_.size(), (pos / unit + 1) * unit);
  for (std::size_t i = pos; i < end; ++i) {
    const auto noise = static_cast<std::uint8_t>(rng_());
    // Flash programming only clears bits and erasing only sets them; an EEPROM cell can be
    // anything.
    if (kind_ == SimMedium::kEeprom)
      bytes_[i] = noise;
    else if (erasing)
      bytes_[i] |= noise;
    else
      bytes_[i] &= noise;
  }
}

Status SimNvStorage::read(std::size_t off, std::span<std::uint8_t> out) {
  if (!powered_) return power_lost();
  if (off > bytes_.size() || out.size() > bytes_.size() - off)
    return make_error(Errc::kInvalidArgument, "read beyond the end of the medium");
  std::copy_n(bytes_.begin() + static_cast<std::ptrdiff_t>(off), out.size(), out.begin());
  return Ok{};
}

Status SimNvStorage::write(std::size_t off, std::span<const std::uint8_t> data) {
  if (!powered_) return power_lost();
  if (off > bytes_.size() || data.size() > bytes_.size() - off)
    return make_error(Errc::kInvalidArgument, "write beyond the end of the medium");
  for (std::size_t i = 0; i < data.size(); ++i) {
    if (!step()) {
      tear_from(off + i, false);
      return power_lost();
    }
    if (kind_ == SimMedium::kFlash)
      bytes_[off + i] &= data[i];
    else
      bytes_[off + i] = data[i];
  }
  return Ok{};
}

Status SimNvStorage::erase(std::size_t off, std::size_t len) {
  if (!powered_) return power_lost();
  if (off > bytes_.size() || len > bytes_.size() - off)
    return make_error(Errc::kInvalidArgument, "erase beyond the end of the medium");
  if (erase_block_ > 0 && (off % erase_block_ != 0 || len % erase_block_ != 0))
    return make_error(Errc::kInvalidArgument, "erase range " + std::to_string(off) + "+" +
                                                  std::to_string(len) +
                                                  " is not aligned to the erase block of " +
                                                  std::to_string(erase_block_) + " bytes");
  for (std::size_t i = 0; i < len; ++i) {
    if (!step()) {
      tear_from(off + i, erase_block_ > 0);
      return power_lost();
    }
    bytes_[off + i] = 0xFF;
  }
  return Ok{};
}

}  // namespace odo::sim
