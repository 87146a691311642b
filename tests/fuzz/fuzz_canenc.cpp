// Fuzz target: received encoder-count frames (odo::drivers::decode_count and CanEncoderSource),
// and the same frames as yaw-rate frames (CanGyroSource, which decodes its field alike).
// Input: byte 0 chooses the layout (width 16..64 bits, signedness, byte order, 11/29-bit ids,
// ODrive or generic), byte 1 the byte offsets, bytes 2-3 the base id; then records of 11 bytes:
// [who, flags, dt_ms, 8 data bytes], who 0/1 = the left/right wheel's id, else a foreign id;
// flags bit 0 extended toggled, bit 1 remote request, bits 4-7 the DLC (0..15, > 8 invalid),
// bit 2: the loop reads after this frame.
// Properties: no crash or UB (ASan, UBSan); a decoded count re-encodes to the frame's bytes and
// lies in the range of its width; samples stay inside counter_bits, carry only the stale and
// jump flags, and their counters never decrease. The gyro (on the left wheel's layout, when its
// width is 16..32 bits) reads on the same records: a finite rate within the field's range, only
// its four flags, starting only before its first sample, and counters that never decrease.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <optional>

#include "fuzz_check.hpp"
#include "odo/drivers/can_encoder.hpp"
#include "odo/drivers/can_gyro.hpp"

namespace {

using odo::CanFrame;
using odo::drivers::CanCountLayout;
using odo::drivers::CanDecode;

// ListBus: hands out the frames queued by the fuzzer; sends are accepted and forgotten.
class ListBus final : public odo::CanBus {
 public:
  odo::CanTx send(const CanFrame&) noexcept override { return odo::CanTx::kSent; }
  bool receive(CanFrame& out) noexcept override {
    if (head_ == n_) return false;
    out = q_[head_++];
    return true;
  }
  void push(const CanFrame& f) noexcept {
    if (n_ == q_.size()) return;
    q_[n_++] = f;
  }

 private:
  std::array<CanFrame, 512> q_{};
  std::size_t n_ = 0, head_ = 0;
};

// check_decoded: the count re-encoded with the layout gives back the frame's bytes.
void check_decoded(const CanFrame& f, const CanCountLayout& l, std::int64_t v) {
  using odo::fuzz::require;
  const int bytes = l.width_bits / 8;
  require(l.byte_offset + bytes <= f.len && f.len <= 8, "decoded a frame too short");
  require(f.id == l.id && f.extended == l.extended && !f.rtr, "decoded a frame of another id");
  const auto u = static_cast<std::uint64_t>(v);
  for (int i = 0; i < bytes; ++i) {
    const int shift = 8 * (l.big_endian ? bytes - 1 - i : i);
    const auto b = static_cast<std::uint8_t>(u >> shift);
    require(b == f.data[static_cast<std::size_t>(l.byte_offset + i)], "count does not re-encode");
  }
  if (l.width_bits < 64) {
    const std::int64_t half = std::int64_t{1} << (l.width_bits - 1);
    if (l.is_signed)
      require(v >= -half && v < half, "signed count outside its width");
    else
      require(v >= 0 && v < 2 * half, "unsigned count outside its width");
  }
}

// Gyro: a CanGyroSource on the left wheel's layout, fed the same frames on a bus of its own.
class Gyro {
 public:
  // Gyro: `sel` picks the sign and offset; no gyro when the layout is not one a gyro takes.
  Gyro(const CanCountLayout& field, std::uint8_t sel) {
    cfg_.field = field;
    cfg_.scale = 1.0 / 4096.0;
    cfg_.offset = (sel & 0x04) != 0 ? -8.0 : 0.0;
    cfg_.sign = (sel & 0x02) != 0 ? -1 : 1;
    cfg_.stale_timeout = 50'000'000;
    cfg_.max_frames_per_read = 16;
    auto made = odo::drivers::CanGyroSource::create(bus_, cfg_);
    if (made) gyro_.emplace(std::move(made).value());
    // The field's ends [rad/s]: |rate| never exceeds the larger.
    const int w = field.width_bits;
    const double lo = field.is_signed ? -std::ldexp(1.0, w - 1) : 0.0;
    const double hi = field.is_signed ? std::ldexp(1.0, w - 1) - 1.0 : std::ldexp(1.0, w) - 1.0;
    bound_ = std::max(std::fabs(lo * cfg_.scale + cfg_.offset),
                      std::fabs(hi * cfg_.scale + cfg_.offset));
  }
  void push(const CanFrame& f) noexcept { bus_.push(f); }
  // read: one read at `now` [ns] and its properties.
  void read(odo::TimeNs now) {
    using odo::fuzz::require;
    if (!gyro_) return;
    const odo::GyroSample s = gyro_->read(now);
    const std::uint32_t allowed =
        odo::kGyroStale | odo::kGyroSaturated | odo::kGyroInvalid | odo::kGyroStarting;
    require((s.flags & ~allowed) == 0, "gyro: unexpected flag");
    require(std::isfinite(s.rate_z) && std::fabs(s.rate_z) <= bound_, "gyro: rate out of range");
    // Starting only before the first sample, this read's included (a read that took one may
    // still be stale: frames beyond max_frames_per_read wait, and the newest taken can be old).
    require((s.flags & odo::kGyroStarting) == 0 || s.counters.samples == 0,
            "gyro: starting after a sample");
    require(s.stamp <= now, "gyro: stamp after the read");
    const odo::GyroCounters& c = s.counters;
    require(c.samples >= last_.samples && c.stale_events >= last_.stale_events &&
                c.saturated >= last_.saturated && c.invalid >= last_.invalid,
            "gyro: a counter went back");
    require(c.samples + c.invalid <= gyro_->stats().frames, "gyro: more samples than frames");
    require(c.read_errors == 0, "gyro: counted a read error this bus cannot give");
    last_ = c;
  }

 private:
  ListBus bus_;
  odo::drivers::CanGyroConfig cfg_;
  std::optional<odo::drivers::CanGyroSource> gyro_;
  double bound_ = 0.0;
  odo::GyroCounters last_{};
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using odo::fuzz::require;
  if (size < 4) return 0;
  odo::drivers::CanEncoderConfig cfg;
  const std::uint8_t sel = data[0];
  if ((sel & 0x80) != 0) {
    cfg.left = odo::drivers::odrive_count_layout(data[2] & 0x3F);
    cfg.right = odo::drivers::odrive_count_layout((data[2] + 1u) & 0x3F);
  } else {
    const int width = 16 + 8 * (sel % 7);
    const int span = 9 - width / 8;  // offsets 0..8-bytes
    const bool ext = (sel & 0x20) != 0;
    const std::uint32_t id = ((std::uint32_t{data[2]} << 8) | data[3]) & (ext ? 0xFFFFu : 0x7FFu);
    for (int w = 0; w < 2; ++w) {
      CanCountLayout& l = w == 0 ? cfg.left : cfg.right;
      l.id = id;
      l.extended = ext;
      l.width_bits = width;
      l.is_signed = (sel & 0x08) != 0;
      l.big_endian = (sel & 0x10) != 0;
      l.byte_offset = (w == 0 ? data[1] & 0x0F : data[1] >> 4) % span;
    }
    if ((sel & 0x40) != 0) cfg.right.id = (id + 1) & (ext ? 0xFFFFu : 0x7FFu);
  }
  cfg.timeout = 50'000'000;
  cfg.max_counts_per_s = 1e5;
  cfg.max_frames_per_read = 16;
  ListBus bus;
  auto made = odo::drivers::CanEncoderSource::create(bus, cfg);
  if (!made) return 0;  // e.g. both wheels on the same bytes
  odo::drivers::CanEncoderSource enc = std::move(made).value();
  const int bits = enc.counter_bits();
  Gyro gyro(cfg.left, sel);
  odo::TimeNs now = 1;
  odo::EncoderCounters last{};
  for (std::size_t at = 4; at + 11 <= size; at += 11) {
    const std::uint8_t* r = data + at;
    CanFrame f;
    const CanCountLayout& mine = r[0] == 0 ? cfg.left : cfg.right;
    f.id = r[0] <= 1 ? mine.id : r[0];
    f.extended = (r[0] <= 1 ? mine.extended : false) != ((r[1] & 0x01) != 0);
    f.rtr = (r[1] & 0x02) != 0;
    f.len = static_cast<std::uint8_t>(r[1] >> 4);
    for (std::size_t i = 0; i < 8; ++i) f.data[i] = r[3 + i];
    now += odo::TimeNs{r[2]} * 1'000'000;
    f.stamp = now;
    for (const CanCountLayout* l : {&cfg.left, &cfg.right}) {
      std::int64_t v = 0;
      if (odo::drivers::decode_count(f, *l, v) == CanDecode::kOk) check_decoded(f, *l, v);
    }
    bus.push(f);
    gyro.push(f);
    if ((r[1] & 0x04) == 0) continue;
    gyro.read(now);
    const odo::EncoderSample s = enc.read(now);
    const std::uint32_t allowed =
        odo::kEncoderStaleLeft | odo::kEncoderStaleRight | odo::kEncoderImplausibleJump;
    require((s.flags & ~allowed) == 0, "unexpected flag");
    if (bits < 64) {
      const std::int64_t half = std::int64_t{1} << (bits - 1);
      require(s.left >= -half && s.left < half && s.right >= -half && s.right < half,
              "count outside counter_bits");
    }
    require(s.counters.stale_events >= last.stale_events &&
                s.counters.implausible_jumps >= last.implausible_jumps,
            "a counter went back");
    require(s.counters.read_errors == 0 && s.counters.invalid_transitions == 0,
            "counted a fault this backend cannot see");
    last = s.counters;
  }
  return 0;
}
