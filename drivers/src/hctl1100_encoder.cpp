#include "odo/drivers/hctl1100_encoder.hpp"

#include <cmath>
#include <cstdlib>
#include <string>

#include "odo/drivers/count_plausibility.hpp"

namespace odo::drivers {
namespace {

constexpr std::uint8_t kRegMsb = 0x12;
constexpr std::uint8_t kRegMid = 0x13;
constexpr std::uint8_t kRegLsb = 0x14;

// wrap24: the low 24 bits of v, sign-extended (two's complement).
constexpr std::int64_t wrap24(std::int64_t v) noexcept {
  return wrap_bits(v, 24);
}

}  // namespace

Result<Hctl1100Encoder> Hctl1100Encoder::create(ParallelBus& bus, const Hctl1100Config& cfg) {
  const int n = bus.units();
  auto bad = [](const std::string& m) { return make_error(Errc::kInvalidArgument, m); };
  if (cfg.unit_left < 0 || cfg.unit_left >= n || cfg.unit_right < 0 || cfg.unit_right >= n)
    return bad("hctl1100: unit_left/unit_right must name one of the bus's " + std::to_string(n) +
               " chip selects (0.." + std::to_string(n - 1) + ")");
  if (cfg.unit_left == cfg.unit_right) return bad("hctl1100: both wheels on the same chip select");
  if (!(cfg.max_counts_per_s > 0.0 && cfg.max_counts_per_s <= 1e8))
    return bad("hctl1100: max_counts_per_s must be in (0, 1e8] counts/s");
  if (auto s = check_row(kHctlAgreeWindow, "hctl1100: ", cfg.agree_window); !s)
    return std::move(s).error();
  if (auto s = check_row(kHctlMaxAttempts, "hctl1100: ", cfg.max_attempts); !s)
    return std::move(s).error();
  return Hctl1100Encoder(bus, cfg);
}

bool Hctl1100Encoder::read_once(int unit, std::int32_t& out) noexcept {
  // LSB first: if the chip latches the upper bytes on the LSB read, this uses the latch.
  const BusRead lo = bus_->read_register(unit, kRegLsb);
  const BusRead mid = bus_->read_register(unit, kRegMid);
  const BusRead hi = bus_->read_register(unit, kRegMsb);
  if (!lo.ok || !mid.ok || !hi.ok) return false;
  const std::uint32_t v =
      (std::uint32_t{hi.value} << 16) | (std::uint32_t{mid.value} << 8) | lo.value;
  out = static_cast<std::int32_t>(v << 8) >> 8;
  return true;
}

bool Hctl1100Encoder::read_position(int unit, std::int32_t& out) noexcept {
  std::int32_t prev = 0;
  if (!read_once(unit, prev)) return false;
  for (int i = 1; i < cfg_.max_attempts; ++i) {
    std::int32_t cur = 0;
    if (!read_once(unit, cur)) return false;
    if (std::llabs(wrap24(std::int64_t{cur} - prev)) <= cfg_.agree_window) {
      out = cur;
      return true;
    }
    prev = cur;
  }
  return false;
}

EncoderSample Hctl1100Encoder::read(TimeNs now) noexcept {
  EncoderSample s;
  s.stamp = now;
  const double dt = have_stamp_ ? to_seconds(now - last_stamp_) : 0.0;
  const std::array<int, 2> units{cfg_.unit_left, cfg_.unit_right};
  const std::array<bool, 2> reverse{cfg_.reverse_left, cfg_.reverse_right};
  std::array<std::int64_t, 2> out{};
  bool all_ok = true;
  for (int i = 0; i < 2; ++i) {
    Wheel& w = wheel_[i];
    std::int32_t pos = 0;
    if (!read_position(units[i], pos)) {
      // Nothing is integrated from this wheel this tick; the next good reading carries the
      // motion because the counts are cumulative.
      all_ok = false;
      out[i] = w.last_out;
      continue;
    }
    const std::int64_t raw = reverse[i] ? wrap24(-std::int64_t{pos}) : pos;
    if (w.primed) {
      const std::int64_t step = wrap24(raw - w.last_raw);
      // The largest step the wheel can make since the last accepted reading, plus the motion
      // allowed inside one reading.
      if (implausible_step(step, cfg_.max_counts_per_s, dt, cfg_.agree_window + 1.0)) {
        // Report, do not integrate: shift the offset so the reported value stays put.
        w.offset += step;
        ++counters_.implausible_jumps;
        s.flags |= kEncoderImplausibleJump;
      }
    }
    w.last_raw = raw;
    w.primed = true;
    w.last_out = wrap24(raw - w.offset);
    out[i] = w.last_out;
  }
  if (!all_ok) {
    ++counters_.read_errors;
    s.flags |= kEncoderReadError;
  } else {
    // dt is measured between complete readings, so a failed tick widens the next window.
    last_stamp_ = now;
    have_stamp_ = true;
  }
  s.left = out[0];
  s.right = out[1];
  s.left_rejected = wheel_[0].offset;  // the chip holds out + offset (24-bit wrap)
  s.right_rejected = wheel_[1].offset;
  s.counters = counters_;
  return s;
}

}  // namespace odo::drivers
