#include "odo/drivers/gpio_quadrature.hpp"

#include <gpiod.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cerrno>
#include <ctime>
#include <string>
#include <thread>
#include <vector>

#include "gpiod_util.hpp"
#include "odo/drivers/monotonic_clock.hpp"
#include "odo/drivers/quad_tracker.hpp"
#include "odo/hal/side_sample.hpp"

namespace odo::drivers {
namespace {

enum class Role : std::uint8_t { kA, kB, kIndex };

constexpr int kMaxWheels = 2 * kMaxWheelsPerSide;
constexpr int kMaxLines = 3 * kMaxWheels;  // A, B and index of every wheel

struct LineRole {
  int wheel = 0;
  Role role = Role::kA;
};

struct Event {
  TimeNs ts = 0;
  std::uint8_t line = 0;  // index into the request bulk
  bool rising = false;
  bool done = false;  // consumed as part of an earlier same-timestamp group
};

// The published state of one wheel: written by the event thread, read by the loop.
struct WheelAtomics {
  std::atomic<std::int64_t> count{0};
  std::atomic<std::uint64_t> received{0};
  std::atomic<std::uint64_t> edges{0};
  std::atomic<std::uint64_t> invalid{0};
  std::atomic<std::uint64_t> index_pulses{0};
  std::atomic<std::int64_t> index_count{0};
  std::atomic<std::uint64_t> dropped{0};
};

// gpio_wheel_count: 2 * wheels_per_side (clamped to 1..kMaxWheelsPerSide per side).
int gpio_wheel_count(const GpioQuadratureConfig& cfg) noexcept {
  return 2 * std::clamp(cfg.wheels.wheels_per_side, 1, kMaxWheelsPerSide);
}

}  // namespace

const GpioWheelLines& gpio_wheel_lines(const GpioQuadratureConfig& cfg, int i) noexcept {
  return wheel_of_side(i, cfg.left, cfg.right, cfg.more_left, cfg.more_right);
}

struct GpioQuadratureEncoder::Impl {
  GpioQuadratureConfig cfg;
  ChipHandle chip;
  gpiod_line_bulk bulk{};
  std::array<LineRole, kMaxLines> roles{};
  unsigned n_lines = 0;
  int n_wheels = 2;  // 2 * wheels_per_side
  std::array<QuadTracker, kMaxWheels> trackers{};
  std::array<std::uint64_t, kMaxWheels> edges{};
  std::array<std::uint64_t, kMaxWheels> index_pulses{};
  std::array<std::int64_t, kMaxWheels> index_count{};
  std::array<TimeNs, kMaxWheels> last_ts{};  // timestamp of the last applied A/B edge per wheel
  TimeNs seen_ts[kMaxWheels][2] = {};        // newest received timestamp per wheel and line (A, B)
  std::uint64_t events_read = 0;             // all events read from the kernel
  bool suspect = false;                      // idle check saw a difference once
  std::array<QuadState, kMaxWheels> suspect_levels{};
  std::uint64_t suspect_events = 0;  // events_read when the idle check first saw a difference
  std::array<WheelAtomics, kMaxWheels> pub;
  std::atomic<bool> stop{false};
  std::atomic<bool> held{false};
  std::atomic<bool> failed{false};
  std::vector<Event> pending;         // sorted by timestamp after each round
  std::vector<gpiod_line_event> buf;  // one batch
  std::thread thread;

  std::int64_t signed_count(int w) const noexcept {
    const bool rev = gpio_wheel_lines(cfg, w).reverse;
    return rev ? -trackers[w].count() : trackers[w].count();
  }
  void publish() noexcept {
    for (int w = 0; w < n_wheels; ++w) {
      pub[w].edges.store(edges[w], std::memory_order_relaxed);
      pub[w].invalid.store(trackers[w].invalid(), std::memory_order_relaxed);
      pub[w].index_pulses.store(index_pulses[w], std::memory_order_relaxed);
      pub[w].index_count.store(index_count[w], std::memory_order_relaxed);
      pub[w].count.store(signed_count(w), std::memory_order_release);
    }
  }
  bool read_levels(std::array<QuadState, kMaxWheels>& out) noexcept {
    int v[kMaxLines] = {};
    if (gpiod_line_get_value_bulk(&bulk, v) != 0) return false;
    out = {};
    for (unsigned i = 0; i < n_lines; ++i) {
      const LineRole r = roles[i];
      if (r.role == Role::kIndex || v[i] == 0) continue;
      out[r.wheel] |= r.role == Role::kA ? QuadTracker::kLineA : QuadTracker::kLineB;
    }
    return true;
  }
  // read_line: appends line l's waiting events to `pending`, counting what does not fit;
  // false when the kernel refuses the read.
  bool read_line(gpiod_line* l) noexcept;
  // sort_pending: `pending` in timestamp order (stable, in place).
  void sort_pending() noexcept;
  // ready_count: how many of the oldest pending events may be applied at read time t_read.
  std::size_t ready_count(TimeNs t_read) const noexcept;
  void process(std::size_t n) noexcept;
  void idle_check() noexcept;
  void run() noexcept;
  // add_lines: every wheel's A, B and index line (cfg) into `bulk` with its role; errors name
  // the line and its role.
  Status add_lines();
};

void GpioQuadratureEncoder::Impl::process(std::size_t n) noexcept {
  for (std::size_t i = 0; i < n; ++i) {
    Event& e = pending[i];
    if (e.done) continue;
    const LineRole r = roles[e.line];
    e.done = true;
    if (r.role == Role::kIndex) {
      if (e.rising) {
        ++index_pulses[r.wheel];
        index_count[r.wheel] = signed_count(r.wheel);
      }
      continue;
    }
    // This wheel's A/B events with the same timestamp changed at the same instant: one
    // transition (both lines changing is the illegal one).
    std::uint8_t mask = r.role == Role::kA ? QuadTracker::kLineA : QuadTracker::kLineB;
    std::uint8_t levels = e.rising ? mask : 0;
    for (std::size_t j = i + 1; j < n && pending[j].ts == e.ts; ++j) {
      Event& o = pending[j];
      const LineRole ro = roles[o.line];
      if (o.done || ro.wheel != r.wheel || ro.role == Role::kIndex) continue;
      const std::uint8_t bit = ro.role == Role::kA ? QuadTracker::kLineA : QuadTracker::kLineB;
      if (mask & bit) continue;  // the same line again: its own transition, later
      mask |= bit;
      if (o.rising) levels |= bit;
      o.done = true;
    }
    if (e.ts < last_ts[r.wheel]) {
      // Arrived after a younger edge of the other line was already applied (the kernel's IRQ
      // thread ran later than the reorder window): report it instead of miscounting.
      trackers[r.wheel].adopt(mask, levels);
    } else {
      trackers[r.wheel].apply(mask, levels);
      last_ts[r.wheel] = e.ts;
    }
    edges[r.wheel] += (mask == 3u) ? 2 : 1;
  }
}

void GpioQuadratureEncoder::Impl::idle_check() noexcept {
  // A difference between the lines and the decoded state counts as lost edges only when it was
  // seen at two idle checks in a row (idle_check apart) with not one event read in between:
  // an edge whose event is merely late (the kernel's IRQ thread not yet run) is not a loss.
  std::array<QuadState, kMaxWheels> now{};
  if (!read_levels(now)) return;
  bool differs = false;
  for (int w = 0; w < n_wheels; ++w) differs = differs || now[w] != trackers[w].state();
  if (!differs) {
    suspect = false;
    return;
  }
  if (suspect && suspect_levels == now && suspect_events == events_read) {
    for (int w = 0; w < n_wheels; ++w) trackers[w].resync(now[w]);
    suspect = false;
    return;
  }
  suspect = true;
  suspect_levels = now;
  suspect_events = events_read;
}

bool GpioQuadratureEncoder::Impl::read_line(gpiod_line* l) noexcept {
  unsigned idx = 0;
  while (idx < n_lines && gpiod_line_bulk_get_line(&bulk, idx) != l) ++idx;
  const int got = gpiod_line_event_read_multiple(l, buf.data(), static_cast<unsigned>(buf.size()));
  if (got < 0) return false;
  const BatchSplit split =
      split_batch(static_cast<std::size_t>(got), pending.capacity() - pending.size());
  if (split.dropped > 0)
    pub[roles[idx].wheel].dropped.fetch_add(split.dropped, std::memory_order_relaxed);
  for (std::size_t e = 0; e < split.taken; ++e) {
    const gpiod_line_event& ev = buf[e];
    const TimeNs ts = static_cast<TimeNs>(ev.ts.tv_sec) * kNsPerSecond + ev.ts.tv_nsec;
    ++events_read;
    if (roles[idx].role != Role::kIndex) {
      pub[roles[idx].wheel].received.fetch_add(1, std::memory_order_relaxed);
      seen_ts[roles[idx].wheel][roles[idx].role == Role::kA ? 0 : 1] = ts;
    }
    pending.push_back(Event{ts, static_cast<std::uint8_t>(idx),
                            ev.event_type == GPIOD_LINE_EVENT_RISING_EDGE, false});
  }
  return true;
}

void GpioQuadratureEncoder::Impl::sort_pending() noexcept {
  // Each line's events arrive in order, so the buffer is nearly sorted: an insertion sort
  // merges the lines by timestamp in place (stable: equal stamps keep their read order) and,
  // unlike std::stable_sort, allocates nothing.
  for (std::size_t k = 1; k < pending.size(); ++k) {
    const Event e = pending[k];
    std::size_t m = k;
    for (; m > 0 && pending[m - 1].ts > e.ts; --m) pending[m] = pending[m - 1];
    pending[m] = e;
  }
}

std::size_t GpioQuadratureEncoder::Impl::ready_count(TimeNs t_read) const noexcept {
  // An A/B edge is ready when the wheel's other line has delivered a younger edge (each
  // line's queue is in order, so nothing older of that line can still come) or when it is
  // older than the reorder window (the other line may simply not have moved). While the
  // wheel turns, A and B alternate, so the order is exact whatever the kernel's latency.
  // Everything is ready when the buffer is nearly full.
  const TimeNs cutoff = t_read - cfg.reorder_window;
  const bool flush = pending.size() * 4 >= pending.capacity() * 3;
  std::size_t n = 0;
  while (n < pending.size()) {
    const Event& e = pending[n];
    const LineRole role = roles[e.line];
    const bool other_newer =
        role.role != Role::kIndex && seen_ts[role.wheel][role.role == Role::kA ? 1 : 0] > e.ts;
    if (!(flush || other_newer || e.ts <= cutoff)) break;
    ++n;
  }
  return n;
}

void GpioQuadratureEncoder::Impl::run() noexcept {
  TimeNs last_activity = monotonic_now();
  while (!stop.load(std::memory_order_relaxed)) {
    if (held.load(std::memory_order_relaxed)) {
      sleep_ns(1'000'000);
      last_activity = monotonic_now();
      continue;
    }
    // Short timeout while events wait for their reorder window; otherwise idle-check period.
    const TimeNs wait =
        pending.empty() ? std::min<TimeNs>(cfg.idle_check, 100'000'000) : cfg.reorder_window;
    timespec to{static_cast<time_t>(wait / kNsPerSecond), static_cast<long>(wait % kNsPerSecond)};
    gpiod_line_bulk evb;
    const int r = gpiod_line_event_wait_bulk(&bulk, &to, &evb);
    const TimeNs t_read = monotonic_now();  // before the reads: the reorder cutoff's origin
    bool ok = r >= 0;
    for (unsigned k = 0; r > 0 && ok && k < gpiod_line_bulk_num_lines(&evb); ++k)
      ok = read_line(gpiod_line_bulk_get_line(&evb, k));
    if (!ok) {
      failed.store(true, std::memory_order_release);
      return;
    }
    if (r > 0) last_activity = t_read;
    if (pending.empty()) {
      if (r == 0 && t_read - last_activity >= cfg.idle_check) {
        idle_check();
        publish();
        last_activity = monotonic_now();
      }
      continue;
    }
    sort_pending();
    const std::size_t n = ready_count(t_read);
    if (n == 0) continue;
    process(n);
    pending.erase(pending.begin(), pending.begin() + static_cast<std::ptrdiff_t>(n));
    publish();
  }
}

GpioQuadratureEncoder::GpioQuadratureEncoder(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}

GpioQuadratureEncoder::~GpioQuadratureEncoder() {
  impl_->stop.store(true);
  if (impl_->thread.joinable()) impl_->thread.join();
}

Status GpioQuadratureEncoder::Impl::add_lines() {
  struct Want {
    int offset;
    LineRole role;
    std::string name;
  };
  n_wheels = gpio_wheel_count(cfg);
  std::vector<Want> wants;
  for (int i = 0; i < n_wheels; ++i) {
    const GpioWheelLines& l = gpio_wheel_lines(cfg, i);
    std::string side = i % 2 == 0 ? "left" : "right";
    if (n_wheels > 2) side += " " + std::to_string(i / 2 + 1);
    wants.push_back({static_cast<int>(l.a), {i, Role::kA}, side + " a"});
    wants.push_back({static_cast<int>(l.b), {i, Role::kB}, side + " b"});
    wants.push_back({l.index, {i, Role::kIndex}, side + " index"});
  }
  std::vector<int> used;
  for (const Want& w : wants) {
    if (w.offset < 0) continue;
    if (std::find(used.begin(), used.end(), w.offset) != used.end())
      return make_error(Errc::kInvalidArgument, "gpio: line " + std::to_string(w.offset) + " (" +
                                                    w.name + ") is used twice");
    used.push_back(w.offset);
    gpiod_line* l = get_line(chip.get(), static_cast<unsigned>(w.offset));
    if (l == nullptr) {
      errno = 0;
      return line_error(cfg.chip, static_cast<unsigned>(w.offset), w.name.c_str());
    }
    gpiod_line_bulk_add(&bulk, l);
    roles[n_lines++] = w.role;
  }
  return Ok{};
}

Result<std::unique_ptr<GpioQuadratureEncoder>> GpioQuadratureEncoder::open(
    const GpioQuadratureConfig& cfg) {
  if (auto s = check_row(kGpioBatch, "gpio: ", cfg.batch); !s) return std::move(s).error();
  if (cfg.reorder_window < 0 || cfg.reorder_window > 100'000'000)
    return make_error(Errc::kInvalidArgument, "gpio: reorder_window must be in [0, 0.1] s");
  if (cfg.idle_check < 10'000'000 || cfg.idle_check > 10 * kNsPerSecond)
    return make_error(Errc::kInvalidArgument, "gpio: idle_check must be in [0.01, 10] s");
  if (cfg.wheels.wheels_per_side < 1 || cfg.wheels.wheels_per_side > kMaxWheelsPerSide)
    return make_error(Errc::kInvalidArgument,
                      "gpio: wheels_per_side must be 1.." + std::to_string(kMaxWheelsPerSide));
  std::optional<SideCombiner> combiner;
  if (cfg.wheels.wheels_per_side > 1) {
    SideWheelsConfig w = cfg.wheels;
    w.counter_bits = 64;  // each wheel's count is a 64-bit integer of the decoder
    auto c = SideCombiner::create(w);
    if (!c) return std::move(c).error();
    combiner.emplace(std::move(c).value());
  }
  auto impl = std::make_unique<Impl>();
  impl->cfg = cfg;
  auto chip = open_chip(cfg.chip);
  if (!chip) return std::move(chip).error();
  impl->chip = std::move(chip).value();
  gpiod_line_bulk_init(&impl->bulk);
  if (Status st = impl->add_lines(); !st) return std::move(st).error();
  const int flags = cfg.active_low ? GPIOD_LINE_REQUEST_FLAG_ACTIVE_LOW : 0;
  if (gpiod_line_request_bulk_both_edges_events_flags(&impl->bulk, cfg.consumer.c_str(), flags) !=
      0)
    return line_error(cfg.chip, cfg.left.a, "encoder lines");
  std::array<QuadState, kMaxWheels> levels{};
  if (!impl->read_levels(levels))
    return make_error(Errc::kIo, "GPIO chip '" + cfg.chip + "': cannot read the encoder lines");
  for (int w = 0; w < impl->n_wheels; ++w) impl->trackers[w].reset(levels[w]);
  impl->buf.resize(static_cast<std::size_t>(cfg.batch));
  impl->pending.reserve(8192);
  Impl* raw = impl.get();
  impl->thread = std::thread([raw] { raw->run(); });
  std::unique_ptr<GpioQuadratureEncoder> enc(new GpioQuadratureEncoder(std::move(impl)));
  enc->combiner_ = std::move(combiner);
  return enc;
}

EncoderSample GpioQuadratureEncoder::read(TimeNs now) noexcept {
  EncoderSample s;
  s.stamp = now;
  s.left = impl_->pub[0].count.load(std::memory_order_acquire);
  s.right = impl_->pub[1].count.load(std::memory_order_acquire);
  std::uint64_t inv = 0;
  for (int w = 0; w < impl_->n_wheels; ++w)
    inv += impl_->pub[w].invalid.load(std::memory_order_relaxed);
  if (inv != last_invalid_) s.flags |= kEncoderInvalidTransition;
  last_invalid_ = inv;
  s.counters.invalid_transitions = inv;
  const bool failed = impl_->failed.load(std::memory_order_acquire);
  if (failed) {
    s.flags |= kEncoderReadError;
    s.counters.read_errors = 1;
  }
  if (combiner_) combine(failed, s);
  return s;
}

void GpioQuadratureEncoder::combine(bool failed, EncoderSample& s) noexcept {
  std::array<SideReadings, 2> side{};
  for (int w = 0; w < impl_->n_wheels; ++w) {
    const auto k = static_cast<std::size_t>(w / 2);
    SideReadings& r = side[static_cast<std::size_t>(w % 2)];
    r.counts[k] = impl_->pub[w].count.load(std::memory_order_acquire);
    // An invalid transition on this wheel's lines since the last read: steps of this wheel may
    // be lost (or its levels adopted), so its count is not trusted this read.
    const std::uint64_t inv = impl_->pub[w].invalid.load(std::memory_order_relaxed);
    if (failed || inv != wheel_invalid_[static_cast<std::size_t>(w)])
      r.faulted = static_cast<std::uint8_t>(r.faulted | (1u << k));
    wheel_invalid_[static_cast<std::size_t>(w)] = inv;
  }
  apply_side_step(combiner_->step(side[0], side[1]), combiner_->counters(), s);
}

GpioWheelStats GpioQuadratureEncoder::wheel(int i) const noexcept {
  const WheelAtomics& a = impl_->pub[i >= 0 && i < impl_->n_wheels ? i : (i == 0 ? 0 : 1)];
  GpioWheelStats s;
  s.count = a.count.load(std::memory_order_acquire);
  s.received = a.received.load(std::memory_order_relaxed);
  s.edges = a.edges.load(std::memory_order_relaxed);
  s.invalid = a.invalid.load(std::memory_order_relaxed);
  s.index_pulses = a.index_pulses.load(std::memory_order_relaxed);
  s.index_count = a.index_count.load(std::memory_order_relaxed);
  s.dropped = a.dropped.load(std::memory_order_relaxed);
  return s;
}

void GpioQuadratureEncoder::hold(bool on) noexcept {
  impl_->held.store(on, std::memory_order_relaxed);
}

}  // namespace odo::drivers
