#include "odo/drivers/gpiod_parallel_bus.hpp"

#include <gpiod.h>

#include "gpiod_util.hpp"

namespace odo::drivers {

struct GpiodParallelBus::Impl {
  GpiodBusConfig cfg;
  ChipHandle chip;
  gpiod_line_bulk ad{};
  gpiod_line* ale = nullptr;
  gpiod_line* oe = nullptr;
  gpiod_line* rw = nullptr;
  std::vector<gpiod_line*> cs;

  void settle() const noexcept { sleep_ns(cfg.settle); }
  void phase(int unit, BusPhaseHook::Phase p) const noexcept {
    if (cfg.hook != nullptr) cfg.hook->on_phase(unit, p);
  }
  // Closing the chip (ChipHandle) releases every requested line.
};

GpiodParallelBus::GpiodParallelBus(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
GpiodParallelBus::~GpiodParallelBus() = default;

int GpiodParallelBus::units() const noexcept {
  return static_cast<int>(impl_->cs.size());
}

Result<std::unique_ptr<GpiodParallelBus>> GpiodParallelBus::open(const GpiodBusConfig& cfg) {
  if (cfg.cs.empty() || cfg.cs.size() > 4)
    return make_error(Errc::kInvalidArgument, "hctl1100 bus: 1 to 4 chip-select lines needed");
  auto impl = std::make_unique<Impl>();
  impl->cfg = cfg;
  auto chip = open_chip(cfg.chip);
  if (!chip) return std::move(chip).error();
  impl->chip = std::move(chip).value();
  const char* who = cfg.consumer.c_str();
  const int ctl_flags = cfg.control_active_low ? GPIOD_LINE_REQUEST_FLAG_ACTIVE_LOW : 0;
  // Control lines start released (logical 0); ALE low, R/W read.
  auto out = [&](unsigned off, int flags, int init, const char* name) -> Result<gpiod_line*> {
    gpiod_line* l = get_line(impl->chip.get(), off);
    if (l == nullptr || gpiod_line_request_output_flags(l, who, flags, init) != 0)
      return line_error(cfg.chip, off, name);
    return l;
  };
  auto ale = out(cfg.ale, 0, 0, "ale");
  if (!ale) return std::move(ale).error();
  impl->ale = *ale;
  auto oe = out(cfg.oe, ctl_flags, 0, "oe");
  if (!oe) return std::move(oe).error();
  impl->oe = *oe;
  auto rw = out(cfg.rw, 0, 1, "rw");
  if (!rw) return std::move(rw).error();
  impl->rw = *rw;
  for (unsigned off : cfg.cs) {
    auto c = out(off, ctl_flags, 0, "cs");
    if (!c) return std::move(c).error();
    impl->cs.push_back(*c);
  }
  gpiod_line_bulk_init(&impl->ad);
  for (unsigned off : cfg.ad) {
    gpiod_line* l = get_line(impl->chip.get(), off);
    if (l == nullptr) return line_error(cfg.chip, off, "ad");
    gpiod_line_bulk_add(&impl->ad, l);
  }
  if (gpiod_line_request_bulk_input(&impl->ad, who) != 0)
    return line_error(cfg.chip, cfg.ad[0], "ad0..ad7");
  return std::unique_ptr<GpiodParallelBus>(new GpiodParallelBus(std::move(impl)));
}

BusRead GpiodParallelBus::read_register(int unit, std::uint8_t reg) noexcept {
  Impl& m = *impl_;
  if (unit < 0 || unit >= static_cast<int>(m.cs.size())) return {};
  gpiod_line* cs = m.cs[static_cast<std::size_t>(unit)];
  int addr[8];
  for (int i = 0; i < 8; ++i) addr[i] = (reg >> i) & 1;
  bool ok = gpiod_line_set_direction_output_bulk(&m.ad, addr) == 0;
  ok = ok && gpiod_line_set_value(m.rw, 1) == 0;
  ok = ok && gpiod_line_set_value(m.ale, 1) == 0;
  ok = ok && gpiod_line_set_value(cs, 1) == 0;
  m.settle();
  // The chip latches the address on the falling edge of ALE.
  ok = ok && gpiod_line_set_value(m.ale, 0) == 0;
  m.settle();
  if (ok) m.phase(unit, BusPhaseHook::Phase::kAddressLatched);
  ok = ok && gpiod_line_set_direction_input_bulk(&m.ad) == 0;
  ok = ok && gpiod_line_set_value(m.oe, 1) == 0;
  m.settle();
  if (ok) m.phase(unit, BusPhaseHook::Phase::kOutputEnabled);
  int data[8] = {};
  ok = ok && gpiod_line_get_value_bulk(&m.ad, data) == 0;
  // Release the bus even after a failure, so the chip never drives AD against us.
  const bool released = gpiod_line_set_value(m.oe, 0) == 0 && gpiod_line_set_value(cs, 0) == 0;
  m.settle();
  m.phase(unit, BusPhaseHook::Phase::kReleased);
  if (!ok || !released) return {};
  std::uint8_t v = 0;
  for (int i = 0; i < 8; ++i) v = static_cast<std::uint8_t>(v | ((data[i] != 0 ? 1 : 0) << i));
  return {v, true};
}

}  // namespace odo::drivers
