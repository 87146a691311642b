#include "odo/drivers/can_encoder.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "odo/drivers/count_plausibility.hpp"
#include "odo/hal/bytes.hpp"
#include "odo/hal/side_sample.hpp"

namespace odo::drivers {
namespace {

constexpr std::uint32_t kOdriveGetEncoderCount = 0x00A;
constexpr std::uint32_t kMaxStdId = 0x7FF;
constexpr std::uint32_t kMaxExtId = 0x1FFFFFFF;
// The jump limit's time tolerance [s]. A frame's count is latched by the controller at l_k and
// stamped by the kernel on arrival at a_k = l_k + d_k, with the sender's latency d_k (its message
// timer, the transmit queue, bus arbitration) in [d_min, d_max]. The wheel can move at most
// v_max * (l_k - l_(k-1)) = v_max * (a_k - a_(k-1) - (d_k - d_(k-1))) <= v_max * (a_k - a_(k-1)
// + J) with the latency jitter J = d_max - d_min: the stamps' difference plus J is the time to
// allow, never the time between the loop's reads (a frame read late by the loop and the next
// read early made that far shorter, issue 39). J = 5 ms covers an ODrive's cyclic timer jitter
// (1 ms ticks) and a full-length frame queued behind a 1 Mbit/s bus at full load for a few ms.
constexpr double kLatencySlack = 0.005;

}  // namespace

CanCountLayout odrive_count_layout(std::uint32_t node_id) noexcept {
  CanCountLayout l;
  l.id = (node_id << 5) | kOdriveGetEncoderCount;
  l.extended = false;
  l.byte_offset = 0;  // shadow count; the count-in-CPR follows at byte 4
  l.width_bits = 32;
  l.is_signed = true;
  l.big_endian = false;
  return l;
}

CanDecode decode_count(const CanFrame& f, const CanCountLayout& layout,
                       std::int64_t& out) noexcept {
  if (f.id != layout.id || f.extended != layout.extended) return CanDecode::kOtherId;
  if (f.rtr) return CanDecode::kRemote;
  const int bytes = layout.width_bits / 8;
  if (layout.byte_offset < 0 || bytes < 1 || bytes > 8 || layout.byte_offset + bytes > 8 ||
      f.len > 8 || layout.byte_offset + bytes > f.len)
    return CanDecode::kShortFrame;
  const std::uint8_t* p = f.data.data() + layout.byte_offset;
  const auto n = static_cast<std::size_t>(bytes);
  const std::uint64_t v = layout.big_endian ? get_be(p, n) : get_le(p, n);
  const int bits = bytes * 8;
  if (layout.is_signed) {
    out = wrap_bits(static_cast<std::int64_t>(v), bits);
  } else {
    out = static_cast<std::int64_t>(v);  // zero-extended; 64-bit values reinterpreted
  }
  return CanDecode::kOk;
}

Status check_layout(const CanCountLayout& l) {
  auto bad = [](const std::string& m) { return make_error(Errc::kInvalidArgument, m); };
  if (!l.extended && l.id > kMaxStdId)
    return bad("id " + std::to_string(l.id) + " does not fit 11 bits (0..2047; set extended)");
  if (l.extended && l.id > kMaxExtId)
    return bad("id " + std::to_string(l.id) + " does not fit 29 bits (0..536870911)");
  if (l.width_bits < 16 || l.width_bits > 64 || l.width_bits % 8 != 0)
    return bad("width " + std::to_string(l.width_bits) +
               " must be 16, 24, 32, 40, 48, 56 or 64 bits (whole bytes; the loop needs >= 16)");
  if (l.byte_offset < 0 || l.byte_offset + l.width_bits / 8 > 8)
    return bad("byte offset " + std::to_string(l.byte_offset) + " + " +
               std::to_string(l.width_bits / 8) + " bytes does not fit the 8 data bytes");
  return Ok{};
}

int can_wheel_count(const CanEncoderConfig& cfg) noexcept {
  const int n = cfg.wheels.wheels_per_side;
  return 2 * (n < 1 ? 1 : (n > kMaxWheelsPerSide ? kMaxWheelsPerSide : n));
}

const CanCountLayout& can_wheel_layout(const CanEncoderConfig& cfg, int i) noexcept {
  return wheel_of_side(i, cfg.left, cfg.right, cfg.more_left, cfg.more_right);
}

namespace {

// wheel_name: "left wheel", "right wheel" (one per side) or "left wheel 2" (several).
std::string wheel_name(const CanEncoderConfig& cfg, int i) {
  std::string n = i % 2 == 0 ? "left wheel" : "right wheel";
  if (cfg.wheels.wheels_per_side > 1) n += " " + std::to_string(i / 2 + 1);
  return n;
}

// check_wheels: every wheel's layout valid, one width, no two wheels on the same bytes.
Status check_wheels(const CanEncoderConfig& cfg) {
  auto bad = [](const std::string& m) { return make_error(Errc::kInvalidArgument, m); };
  const int n = can_wheel_count(cfg);
  for (int i = 0; i < n; ++i) {
    const CanCountLayout& l = can_wheel_layout(cfg, i);
    if (Status s = check_layout(l); !s) return bad(wheel_name(cfg, i) + ": " + s.error().message);
    if (l.width_bits != cfg.left.width_bits)
      return bad(n > 2 ? "all wheels' counts must have the same width"
                       : "both wheels' counts must have the same width");
    for (int j = 0; j < i; ++j) {
      const CanCountLayout& o = can_wheel_layout(cfg, j);
      if (l.id == o.id && l.extended == o.extended && l.byte_offset == o.byte_offset)
        return bad(n > 2 ? wheel_name(cfg, j) + " and " + wheel_name(cfg, i) +
                               " read the same bytes of the same frame"
                         : "both wheels read the same bytes of the same frame");
    }
  }
  return Ok{};
}

}  // namespace

Result<CanEncoderSource> CanEncoderSource::create(CanBus& bus, const CanEncoderConfig& cfg) {
  auto bad = [](const std::string& m) { return make_error(Errc::kInvalidArgument, m); };
  const int per_side = cfg.wheels.wheels_per_side;
  if (per_side < 1 || per_side > kMaxWheelsPerSide)
    return bad("wheels_per_side " + std::to_string(per_side) + " must be 1.." +
               std::to_string(kMaxWheelsPerSide));
  if (Status s = check_wheels(cfg); !s) return std::move(s).error();
  if (cfg.timeout <= 0) return bad("timeout must be > 0 s");
  if (!(cfg.max_counts_per_s > 0.0 && cfg.max_counts_per_s <= 1e9))
    return bad("max_counts_per_s must be in (0, 1e9] counts/s");
  if (auto s = check_row(kCanMaxFramesPerRead, "", cfg.max_frames_per_read); !s)
    return std::move(s).error();
  if (cfg.request_period < 0) return bad("request_period must be >= 0 s");
  CanEncoderSource src(bus, cfg);
  src.cfg_.wheels.counter_bits = cfg.left.width_bits;
  if (per_side > 1) {
    auto c = SideCombiner::create(src.cfg_.wheels);
    if (!c) return std::move(c).error();
    src.combiner_.emplace(std::move(c).value());
  }
  return src;
}

void CanEncoderSource::accept(int i, std::int64_t value, TimeNs stamp,
                              std::uint32_t& flags) noexcept {
  Wheel& w = wheel_[static_cast<std::size_t>(i)];
  const int bits = cfg_.left.width_bits;  // each wheel's own counter (counter_bits() may be 64)
  // Stamps of one socket never go back; a clock conversion could by a few ns: held.
  if (w.primed && stamp < w.last_stamp) stamp = w.last_stamp;
  const bool reverse = i % 2 == 0 ? cfg_.reverse_left : cfg_.reverse_right;
  const std::int64_t raw = reverse ? wrap_sub(0, value, bits) : wrap_bits(value, bits);
  if (!w.primed) {
    // The controller's own counter is reported, so that counts stay continuous across restarts
    // of this process (the loop takes a wheel's first fresh count as its reference).
    w.offset = 0;
    w.primed = true;
  } else {
    const std::int64_t step = wrap_sub(raw, w.last_raw, bits);
    const double dt = to_seconds(stamp - w.last_stamp);
    if (implausible_step(step, cfg_.max_counts_per_s, (dt > 0.0 ? dt : 0.0) + kLatencySlack, 1.0)) {
      // Report, do not integrate: shift the offset so the reported value stays put.
      w.offset = wrap_add(w.offset, step, bits);
      ++counters_.implausible_jumps;
      flags |= kEncoderImplausibleJump;
    }
  }
  w.last_raw = raw;
  w.last_stamp = stamp;
  w.newest = (w.newest + 1) % kHistory;
  w.history[w.newest] = Stamped{stamp, wrap_sub(raw, w.offset, bits)};
  if (w.kept < kHistory) ++w.kept;
}

std::int64_t CanEncoderSource::count_at(const Wheel& w, TimeNs t) const noexcept {
  // Newest first: the frame at or before t, and the one after it.
  std::size_t after = w.newest;
  for (std::size_t k = 0; k < w.kept; ++k) {
    const std::size_t at = (w.newest + kHistory - k) % kHistory;
    const Stamped& f = w.history[at];
    if (f.stamp <= t) {
      if (k == 0) return f.count;  // t at or after the newest frame: its count
      const Stamped& g = w.history[after];
      const int bits = cfg_.left.width_bits;  // each wheel's own counter (counter_bits() may be 64)
      const double frac = static_cast<double>(t - f.stamp) / static_cast<double>(g.stamp - f.stamp);
      const double step = static_cast<double>(wrap_sub(g.count, f.count, bits));
      return wrap_add(f.count, std::llround(frac * step), bits);
    }
    after = at;
  }
  return w.history[after].count;  // before every kept frame: the oldest
}

void CanEncoderSource::send_requests(TimeNs now) noexcept {
  if (cfg_.request_period <= 0 || now < next_request_) return;
  // Skip missed periods: one request per id per period at most, never a burst.
  next_request_ = now + cfg_.request_period;
  const int n = can_wheel_count(cfg_);
  for (int i = 0; i < n; ++i) {
    const CanCountLayout& l = can_wheel_layout(cfg_, i);
    bool asked = false;  // an earlier wheel shares the id: its request answers both
    for (int j = 0; j < i; ++j) {
      const CanCountLayout& o = can_wheel_layout(cfg_, j);
      asked = asked || (o.id == l.id && o.extended == l.extended);
    }
    if (asked) continue;
    CanFrame r;
    r.id = l.id;
    r.extended = l.extended;
    r.rtr = true;
    r.len = 8;
    if (bus_->send(r) == CanTx::kSent)
      ++stats_.requests_sent;
    else
      ++stats_.requests_dropped;
  }
}

int CanEncoderSource::drain(TimeNs now, std::uint32_t& flags) noexcept {
  const int wheels = can_wheel_count(cfg_);
  CanFrame f;
  int n = 0;
  for (; n < cfg_.max_frames_per_read && bus_->receive(f); ++n) {
    ++stats_.frames;
    bool ours = false;
    for (int i = 0; i < wheels; ++i) {
      std::int64_t v = 0;
      switch (decode_count(f, can_wheel_layout(cfg_, i), v)) {
        case CanDecode::kOk:
          // Every frame, not only a read's newest: the jump check and the interpolation work
          // on each frame's own stamp.
          accept(i, v, f.stamp != 0 ? f.stamp : now, flags);
          ++stats_.decoded;
          ours = true;
          break;
        case CanDecode::kRemote:
          if (!ours) ++stats_.remote;
          ours = true;
          break;
        case CanDecode::kShortFrame:
          if (!ours) ++stats_.short_frames;
          ours = true;
          break;
        case CanDecode::kOtherId:
          break;
      }
    }
    if (!ours) ++stats_.foreign;
  }
  return n;
}

void CanEncoderSource::mark_lagging() noexcept {
  const int n = can_wheel_count(cfg_);
  TimeNs horizon = 0;  // the newest among the fresh wheels' oldest kept frames
  for (int i = 0; i < n; ++i) {
    const Wheel& w = wheel_[static_cast<std::size_t>(i)];
    if (w.stale || w.kept == 0) continue;
    horizon = std::max(horizon, w.history[(w.newest + kHistory - (w.kept - 1)) % kHistory].stamp);
  }
  std::array<int, 2> fresh{}, lagging{};
  for (int i = 0; i < n; ++i) {
    Wheel& w = wheel_[static_cast<std::size_t>(i)];
    w.lagging = !w.stale && w.last_stamp < horizon;
    fresh[static_cast<std::size_t>(i % 2)] += w.stale ? 0 : 1;
    lagging[static_cast<std::size_t>(i % 2)] += w.lagging ? 1 : 0;
  }
  // A side whose every fresh wheel lags (a slower sender than the other side's) is held back as
  // with one wheel per side, never dropped for it.
  for (int i = 0; i < n; ++i) {
    const auto side = static_cast<std::size_t>(i % 2);
    if (lagging[side] == fresh[side]) wheel_[static_cast<std::size_t>(i)].lagging = false;
  }
}

TimeNs CanEncoderSource::sample_time(TimeNs now, std::uint32_t& flags) noexcept {
  const int n = can_wheel_count(cfg_);
  std::array<bool, 2> side_fresh{false, false};
  for (int i = 0; i < n; ++i) {
    Wheel& w = wheel_[static_cast<std::size_t>(i)];
    const bool stale = !w.primed || now - w.last_stamp > cfg_.timeout;
    // Several wheels per side: a wheel going stale is a wheel drop, a side going stale an event
    // (both counted by the combiner).
    if (stale && !w.stale && w.primed && !combiner_) ++counters_.stale_events;
    w.stale = stale;
    if (!stale) side_fresh[static_cast<std::size_t>(i % 2)] = true;
  }
  if (combiner_) mark_lagging();
  // A side is stale when none of its wheels is fresh (with one wheel per side: that wheel).
  if (!side_fresh[0]) flags |= kEncoderStaleLeft;
  if (!side_fresh[1]) flags |= kEncoderStaleRight;
  // One instant for all wheels: the oldest newest frame of the fresh wheels (the others
  // interpolated to it; lagging ones left out); with a stale side there is none, and the read
  // time is used as before. Never back in time.
  TimeNs oldest = std::numeric_limits<TimeNs>::max();  // a frame may be stamped after `now`
  for (int i = 0; i < n; ++i) {
    const Wheel& w = wheel_[static_cast<std::size_t>(i)];
    if (!w.stale && !w.lagging) oldest = std::min(oldest, w.last_stamp);
  }
  TimeNs t = side_fresh[0] && side_fresh[1] ? oldest : now;
  if (t < last_sample_) t = last_sample_;
  last_sample_ = t;
  return t;
}

void CanEncoderSource::combine(TimeNs t, EncoderSample& s) noexcept {
  const int n = can_wheel_count(cfg_);
  s.counters = counters_;
  // Before the first frame of any wheel the sides are 0 and stale (sample_time), and no wheel
  // has dropped out of anything (the start-up state is not an event, as with one wheel).
  bool any = false;
  for (int i = 0; i < n; ++i) any = any || wheel_[static_cast<std::size_t>(i)].primed;
  if (!any) return;
  std::array<SideReadings, 2> side{};
  for (int i = 0; i < n; ++i) {
    const Wheel& w = wheel_[static_cast<std::size_t>(i)];
    SideReadings& r = side[static_cast<std::size_t>(i % 2)];
    const int k = i / 2;
    r.counts[static_cast<std::size_t>(k)] = w.primed ? count_at(w, t) : 0;
    // A stale or lagging wheel's count is not this instant's: dropped from the mean.
    if (w.stale || w.lagging) r.faulted = static_cast<std::uint8_t>(r.faulted | (1u << k));
  }
  apply_side_step(combiner_->step(side[0], side[1]), combiner_->counters(), s);
}

EncoderSample CanEncoderSource::read(TimeNs now) noexcept {
  EncoderSample s;
  send_requests(now);
  if (drain(now, s.flags) == cfg_.max_frames_per_read) ++stats_.capped_reads;
  const TimeNs t = sample_time(now, s.flags);
  s.stamp = t;
  if (combiner_) {
    // The combined counts are no controller's counter (they start at 0): nothing to hand back
    // (each wheel's rejected jumps stay in its own offset).
    combine(t, s);
    return s;
  }
  s.left = wheel_[0].primed ? count_at(wheel_[0], t) : 0;
  s.right = wheel_[1].primed ? count_at(wheel_[1], t) : 0;
  s.left_rejected = wheel_[0].offset;  // the controller holds left + offset (issue 39)
  s.right_rejected = wheel_[1].offset;
  s.counters = counters_;
  return s;
}

}  // namespace odo::drivers
