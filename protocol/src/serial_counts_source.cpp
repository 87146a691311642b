#include "odo/protocol/serial_counts_source.hpp"

#include <cstdlib>

#include "odo/hal/side_sample.hpp"
#include "odo/odometry/count_delta.hpp"

namespace odo::protocol {
namespace {

// Bytes received since an open with not one valid sample before kEncoderNoValidData is raised:
// three diffodom frames' worth, or a few bridge answers.
constexpr std::uint64_t kGarbageBytes = 64;

// sign_extend: the low `bits` bits of v as a two's-complement number.
std::int64_t sign_extend(std::int64_t v, int bits) noexcept {
  const int shift = 64 - bits;
  return static_cast<std::int64_t>(static_cast<std::uint64_t>(v) << shift) >> shift;
}

// parse_int: a decimal integer (optional '-') in [p, end); false for anything else.
bool parse_int(const char*& p, const char* end, std::int64_t& out) noexcept {
  bool neg = false;
  if (p < end && (*p == '-' || *p == '+')) neg = *p++ == '-';
  const char* start = p;
  std::int64_t v = 0;
  while (p < end && *p >= '0' && *p <= '9') {
    if (p - start > 12) return false;  // beyond any 32-bit counter
    v = v * 10 + (*p++ - '0');
  }
  if (p == start) return false;
  out = neg ? -v : v;
  return true;
}

}  // namespace

static_assert(kSerialMaxWheelsPerSide == kMaxWheelsPerSide);

SerialCountsSource::SerialCountsSource(ByteLink& link, const SerialSourceConfig& cfg) noexcept
    : link_(&link),
      cfg_(cfg),
      decoder_(cfg.wheels.wheels_per_side > 1),
      clock_(cfg.clock_window, 8) {
  for (std::size_t i = 0; i < wheel_.size(); ++i)
    wheel_[i].bits = i % 2 == 0 ? cfg.bits_left : cfg.bits_right;
  if (cfg.wheels.wheels_per_side > 1) {
    // The config reader checked the numbers (encoder.*); a combiner that cannot be made leaves
    // the source reporting one wheel per side.
    cfg_.wheels.counter_bits = 64;
    if (auto c = SideCombiner::create(cfg_.wheels)) combiner_.emplace(std::move(c).value());
  }
}

void SerialCountsSource::link_gone(TimeNs now, std::uint32_t& flags) noexcept {
  open_ = false;
  next_open_ = now + cfg_.reopen_period;
  ++counters_.read_errors;
  flags |= kEncoderReadError;
}

void SerialCountsSource::try_reopen(TimeNs now, std::uint32_t& flags) noexcept {
  if (now < next_open_) {
    flags |= kEncoderReadError;
    return;
  }
  if (!link_->reopen()) {
    ++stats_.open_failures;
    next_open_ = now + cfg_.reopen_period;
    flags |= kEncoderReadError;
    return;
  }
  open_ = true;
  ++counters_.reconnects;
  // A new connection: whatever was half-received belongs to the old one.
  decoder_.reset();
  synced_ = false;
  line_len_ = 0;
  line_overrun_ = false;
  awaiting_ = false;
  bytes_since_open_ = valid_since_open_ = 0;
}

void SerialCountsSource::link_error(bool crc, std::uint32_t& flags) noexcept {
  ++(crc ? stats_.crc_errors : stats_.bad_frames);
  ++counters_.link_errors;
  flags |= kEncoderLinkError;
}

void SerialCountsSource::accept(std::int64_t left, std::int64_t right, TimeNs stamp,
                                std::uint32_t& flags) noexcept {
  const std::array<std::int64_t, 2> raw{cfg_.reverse_left ? -left : left,
                                        cfg_.reverse_right ? -right : right};
  const double dt = primed_ ? to_seconds(stamp - stamp_) : 0.0;
  std::array<std::int64_t, 2> step{};
  bool jump = false;
  for (std::size_t i = 0; i < 2; ++i) {
    Wheel& w = wheel_[i];
    const std::int64_t r = sign_extend(raw[i], w.bits);
    step[i] = primed_ ? wrap_delta(w.last_raw, r, w.bits) : 0;
    // Slack of 20 ms of motion + 1 count: the stamps of two samples are a transport apart.
    if (std::llabs(step[i]) > static_cast<std::int64_t>(cfg_.max_counts_per_s * (dt + 0.02)) + 1)
      jump = true;
    if (!primed_) w.count = r;  // the controller's own count: continuous across restarts
    w.last_raw = r;
  }
  if (jump) {
    // Report, do not integrate: the counts stay put and the next step starts from here.
    ++counters_.implausible_jumps;
    flags |= kEncoderImplausibleJump;
  } else {
    wheel_[0].count += step[0];
    wheel_[1].count += step[1];
  }
  primed_ = true;
  if (stamp > stamp_) stamp_ = stamp;  // the loop's dt never goes negative
  ++stats_.samples;
  ++valid_since_open_;
}

void SerialCountsSource::on_record(const SerialCounts& c, TimeNs now, TimeNs arrival,
                                   std::uint32_t& flags) noexcept {
  const auto back = static_cast<std::int32_t>(c.time_us - last_time_us_);
  const bool booted_now =
      (c.flags & kSerialFlagBooted) != 0 && (last_flags_ & kSerialFlagBooted) == 0;
  if (primed_ && have_record_ && (booted_now || back < 0)) {
    // The controller restarted: its counters and clock begin again at 0. The motion since its
    // boot (from 0 to these counts) is kept: the counts continue, no spin.
    ++counters_.controller_resets;
    flags |= kEncoderControllerReset;
    for (Wheel& w : wheel_) w.last_raw = 0;
    clock_.reset();
    controller_ns_ = 0;
    have_record_ = false;  // no gap to count against the old sequence
  } else if (!primed_ && (c.flags & kSerialFlagBooted) != 0) {
    // The first record says the controller has just booted: its counts began at 0 since this
    // process last saw them, so a state record of before cannot be continued (resume decision).
    ++counters_.controller_resets;
    flags |= kEncoderControllerReset;
  }
  if (have_record_) {
    const auto expected = static_cast<std::uint16_t>(last_seq_ + 1);
    if (c.seq != expected) {
      ++counters_.sequence_gaps;
      stats_.lost_records += static_cast<std::uint16_t>(c.seq - expected);
      flags |= kEncoderLinkError;
    }
    controller_ns_ += static_cast<std::int64_t>(c.time_us - last_time_us_) * 1000;
  }
  have_record_ = true;
  last_seq_ = c.seq;
  last_time_us_ = c.time_us;
  last_flags_ = c.flags;
  if (combiner_)
    accept_wheels(c, clock_.map(controller_ns_, arrival), flags);
  else
    accept(c.left, c.right, clock_.map(controller_ns_, arrival), flags);
  last_valid_ = now;
}

void SerialCountsSource::accept_wheels(const SerialCounts& c, TimeNs stamp,
                                       std::uint32_t& flags) noexcept {
  const int n = cfg_.wheels.wheels_per_side;
  const double dt = primed_ ? to_seconds(stamp - stamp_) : 0.0;
  // Slack of 20 ms of motion + 1 count, as for one wheel per side.
  const auto limit = static_cast<std::int64_t>(cfg_.max_counts_per_s * (dt + 0.02)) + 1;
  for (int i = 0; i < 2 * n; ++i) {
    const bool right = i % 2 == 1;
    const int k = i / 2;
    const auto& more = right ? c.more_right : c.more_left;
    std::int64_t v = k == 0 ? (right ? c.right : c.left) : more[static_cast<std::size_t>(k - 1)];
    if (right ? cfg_.reverse_right : cfg_.reverse_left) v = -v;
    Wheel& w = wheel_[static_cast<std::size_t>(i)];
    const std::int64_t r = sign_extend(v, w.bits);
    const std::int64_t step = primed_ ? wrap_delta(w.last_raw, r, w.bits) : 0;
    if (!primed_) w.count = r;  // the controller's own count
    w.last_raw = r;
    const auto bit = static_cast<std::uint8_t>(1u << (right ? 4 + k : k));
    // Untrusted (the board says so, or a step no wheel makes): dropped from its side this read;
    // the combiner re-references the wheel when it is clean again. A flagged wheel's count is
    // not judged (garbage is what a fault looks like).
    const bool board_fault = (c.wheel_faults & bit) != 0;
    // The first clean record after a flagged one is the wheel's new start, not a step from the
    // garbage it reported.
    const bool restart = w.faulted && !board_fault;
    w.faulted = board_fault;
    if (restart) continue;
    const bool jump = !board_fault && std::llabs(step) > limit;
    if (jump) ++counters_.implausible_jumps;
    if (jump) flags |= kEncoderImplausibleJump;
    if (jump || board_fault)
      read_faults_ |= bit;
    else
      w.count += step;
  }
  primed_ = true;
  if (stamp > stamp_) stamp_ = stamp;
  ++stats_.samples;
  ++valid_since_open_;
}

void SerialCountsSource::on_byte_diffodom(std::uint8_t b, TimeNs now, TimeNs arrival,
                                          std::uint32_t& flags) noexcept {
  const SerialDecodeResult r = decoder_.push(b);
  if (r == SerialDecodeResult::kNeedMore) return;
  // The first frame after an open may have been joined halfway: not an error of the line.
  const bool first = !synced_;
  synced_ = true;
  // A record with another number of wheels per side than configured is not this robot's.
  const int wheels = combiner_ ? cfg_.wheels.wheels_per_side : 1;
  if (r == SerialDecodeResult::kFrame && decoder_.counts().wheels_per_side == wheels)
    on_record(decoder_.counts(), now, arrival, flags);
  else if (r == SerialDecodeResult::kFrame)
    link_error(false, flags);
  else if (!first)
    link_error(r == SerialDecodeResult::kCrcMismatch, flags);
}

void SerialCountsSource::on_line(TimeNs now, TimeNs arrival, std::uint32_t& flags) noexcept {
  const char* p = line_.data();
  const char* end = p + line_len_;
  if (end > p && end[-1] == '\r') --end;
  if (end - p == 2 && p[0] == 'O' && p[1] == 'K') return;  // the answer to a reset
  std::int64_t l = 0;
  std::int64_t r = 0;
  const bool ok =
      parse_int(p, end, l) && p < end && *p++ == ' ' && parse_int(p, end, r) && p == end;
  if (!ok) {
    link_error(false, flags);
    return;
  }
  // The counts were latched between the request and the answer's arrival.
  const TimeNs stamp = awaiting_ ? request_time_ + (arrival - request_time_) / 2 : arrival;
  awaiting_ = false;
  if (primed_ && l == 0 && r == 0 && (wheel_[0].last_raw != 0 || wheel_[1].last_raw != 0)) {
    // Both counters back at exactly 0: the board restarted (reset, or re-opened: an Arduino
    // resets when the port opens). Continue from here: a jump, not a spin.
    ++counters_.controller_resets;
    flags |= kEncoderControllerReset;
    wheel_[0].last_raw = wheel_[1].last_raw = 0;
  }
  accept(l, r, stamp, flags);
  last_valid_ = now;
}

void SerialCountsSource::on_byte_bridge(std::uint8_t b, TimeNs now, TimeNs arrival,
                                        std::uint32_t& flags) noexcept {
  if (b == '\n') {
    const bool first = !synced_;
    synced_ = true;
    if (line_overrun_)
      link_error(false, flags);
    else if (!first || awaiting_)  // an unasked first line may have been joined halfway
      on_line(now, arrival, flags);
    line_len_ = 0;
    line_overrun_ = false;
    return;
  }
  if (line_len_ < line_.size())
    line_[line_len_++] = static_cast<char>(b);
  else
    line_overrun_ = true;
}

void SerialCountsSource::drain(TimeNs now, std::uint32_t& flags) noexcept {
  // Bounded: a babbling line cannot hold the loop (the rest is read next tick).
  for (int k = 0; k < 64; ++k) {
    TimeNs arrival = now;  // links that do not stamp their input: the read's time
    const int n = link_->read(rx_, arrival);
    if (n < 0) {
      link_gone(now, flags);
      return;
    }
    if (n == 0) return;
    stats_.bytes += static_cast<std::uint64_t>(n);
    bytes_since_open_ += static_cast<std::uint64_t>(n);
    for (int i = 0; i < n; ++i) {
      const std::uint8_t b = rx_[static_cast<std::size_t>(i)];
      if (cfg_.protocol == SerialProtocol::kDiffodom)
        on_byte_diffodom(b, now, arrival, flags);
      else
        on_byte_bridge(b, now, arrival, flags);
    }
  }
}

void SerialCountsSource::poll(TimeNs now) noexcept {
  if (awaiting_ && now - request_time_ > cfg_.timeout) {
    ++stats_.unanswered;  // a board that never answers: stale, and counted here
    awaiting_ = false;
  }
  if (awaiting_ || now < next_poll_) return;
  static constexpr std::uint8_t kRequest[] = {static_cast<std::uint8_t>(kBridgeReadEncoders), '\r'};
  next_poll_ = now + cfg_.poll_period;
  if (!link_->write(kRequest)) return;
  ++stats_.polls;
  request_time_ = now;
  awaiting_ = true;
}

EncoderSample SerialCountsSource::read(TimeNs now) noexcept {
  EncoderSample s;
  if (!open_) try_reopen(now, s.flags);
  if (open_) drain(now, s.flags);
  if (open_ && cfg_.protocol == SerialProtocol::kArduinoBridge) poll(now);
  const bool stale = !primed_ || now - last_valid_ > cfg_.timeout;
  if (stale && !stale_ && primed_) ++counters_.stale_events;
  stale_ = stale;
  if (stale) s.flags |= kEncoderStaleLeft | kEncoderStaleRight;
  if (open_ && bytes_since_open_ >= kGarbageBytes && valid_since_open_ == 0)
    s.flags |= kEncoderNoValidData;
  s.stamp = primed_ ? stamp_ : now;
  s.counters = counters_;
  if (combiner_) {
    combine(s);
    return s;
  }
  s.left = wheel_[0].count;
  s.right = wheel_[1].count;
  return s;
}

void SerialCountsSource::combine(EncoderSample& s) noexcept {
  // Before the first record there are no counts: the sides are 0 and stale (set above), and no
  // wheel has dropped out of anything.
  if (!primed_) return;
  std::array<SideReadings, 2> side{};
  for (int i = 0; i < 2 * cfg_.wheels.wheels_per_side; ++i) {
    const int k = i / 2;
    SideReadings& r = side[static_cast<std::size_t>(i % 2)];
    r.counts[static_cast<std::size_t>(k)] = wheel_[static_cast<std::size_t>(i)].count;
    if ((read_faults_ >> (i % 2 == 1 ? 4 + k : k)) & 1u)
      r.faulted = static_cast<std::uint8_t>(r.faulted | (1u << k));
  }
  read_faults_ = 0;
  apply_side_step(combiner_->step(side[0], side[1]), combiner_->counters(), s);
}

}  // namespace odo::protocol
