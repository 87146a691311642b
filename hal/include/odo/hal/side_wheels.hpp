// SideCombiner: two to four encoders per side of a differential-drive base (4WD, 6WD, tracked),
// combined into the one cumulative count per side the loop integrates, with within-side
// disagreement as a slip cue. Pure: readings in, the sides' counts and flags out; no I/O, no
// allocation, no exceptions (hal is header-only: drivers/, sim_hal/ and board/ link only odo_hal).
//
// Why the mean is the default combination. The wheels of one side are commanded alike and, on a
// rigid body, move over the ground alike; what differs is each wheel's effective radius (tyre
// tolerance, wear, load) and its counts' noise. The mean of N wheels is the side's travel with
// the mean radius (what UMBmark and the self-calibration measure as the side's factor) and its
// random error shrinks as 1/sqrt(N); it needs no ordering, so a count of quantisation never
// decides which wheel is used. The alternatives, per read on the wheels' count deltas:
//   kMedian          the middle wheel (the mean of the two middle ones for 2 and 4): rejects one
//                    spinning wheel among three or four without a detector, but with 2 wheels it
//                    is the mean, and a side's 4 wheels that alternate which one leads by a count
//                    make it follow a different wheel every read (its radius then leaks in).
//   kLeastMagnitude  the wheel that moved least: a spinning or lifted wheel always moves more than
//                    its loaded neighbours, so this ignores it; but on a smooth floor it picks the
//                    smallest radius and, per read, the count that happened to lag: a bias of
//                    about a count per read (short, and 1 % at 100 counts per read), growing with
//                    the read rate. For bases with frequent wheel spin and a gyro absent.
// A wheel that slips still enters the mean: detection flags the interval (the loop then widens the
// covariance and, with a gyro, takes its heading) instead of guessing which wheel is right.
//
// Wrap. Each wheel's counter wraps on its own at counter_bits; every wheel is differenced against
// its own previous reading (wrap_delta), and the side accumulates the combined deltas in a 64-bit
// count in twelfths of a count (12 = lcm(1, 2, 3, 4): a mean over any number of wheels is exact),
// reported rounded to whole counts. The combined count never wraps (counter_bits() == 64).
//
// Faults. A wheel the backend marks faulted is dropped from its side for that read (flag
// kEncoderWheelDropped, event wheel_drops on each wheel's transition into the fault); when it
// returns its reading is the new reference and it rejoins from the next read, so its motion while
// faulted is never added. All wheels of a side faulted: the side keeps its count and is stale
// (kEncoderStaleLeft/Right). A read where every wheel is only (re)gaining its reference (the first
// read) keeps the count, unflagged.
//
// Slip. Over the last `slip_window` seconds (whole reads) each wheel that was clean throughout has
// travelled w_i counts. A side slips when
//     max_i w_i - min_i w_i > slip_counts + slip_fraction |mean_i w_i|
// The absolute part covers quantisation (one count per wheel at each end of the window: 2) and
// the per-wheel count noise of short windows; the relative part covers the radius differences of
// wheels within tolerance (travel differs by the radius ratio) and load-dependent rolling radius.
// A lifted wheel under voltage control spins at its no-load speed, 1 / (1 - l) of a loaded
// wheel's (l the fraction of stall torque the load takes, 0.2-0.3 typically: 25-43 % faster, a
// relative spread of 0.22-0.35 of the mean against the default 0.1); the simulator's figures are
// in BENCHMARKS.md. A slip event is the rising edge of a side's flag (slip_events).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string_view>

#include "odo/hal/choice.hpp"
#include "odo/hal/encoder.hpp"
#include "odo/hal/field_range.hpp"
#include "odo/hal/result.hpp"

namespace odo {

inline constexpr int kMaxWheelsPerSide = 4;
// kMaxSlipWindowReads: the longest slip window in reads (1.28 s at the default 100 Hz loop).
inline constexpr int kMaxSlipWindowReads = 128;

// One side's raw counter readings from one read: counts[i] exactly as wheel i's counter holds
// them (counter_bits wide, sign-extended or not: only the low counter_bits bits are used);
// faulted bit i set when wheel i's reading cannot be trusted this read (stale, an invalid
// transition, a read error of that wheel). Only the first wheels_per_side entries are read.
struct SideReadings {
  std::array<std::int64_t, kMaxWheelsPerSide> counts{};
  std::uint8_t faulted = 0;
};

// How a side's travel is formed from its wheels' travels (see the top of this file).
enum class SideCombine : std::uint8_t { kMean, kMedian, kLeastMagnitude };
inline constexpr Choice<SideCombine> kSideCombineNames[] = {
    {SideCombine::kMean, "mean"},
    {SideCombine::kMedian, "median"},
    {SideCombine::kLeastMagnitude, "least-magnitude"}};

struct SideWheelsConfig {
  int wheels_per_side = 1;  // 1..4 encoders per side (1: the backend does not use the combiner)
  int counter_bits = 32;    // width of each wheel's counter, 16..64 (all wheels of a backend alike)
  SideCombine combine = SideCombine::kMean;
  double slip_window = 0.1;    // [s] over which the wheels' travels are compared (whole reads)
  double slip_counts = 8.0;    // absolute part of the slip threshold [counts]
  double slip_fraction = 0.1;  // relative part: of the side's mean travel over the window
  double read_period = 0.01;   // [s] between reads (the loop's tick): sizes the window
};

// SideParam: every number of SideWheelsConfig the combiner checks; the first kSideConfigParams
// are odometryd's [encoder] keys (by the names of side_wheels_range); read_period is the loop's.
enum class SideParam : std::uint8_t {
  kWheelsPerSide,
  kSlipWindow,
  kSlipCounts,
  kSlipFraction,
  kCounterBits,
  kReadPeriod,
};
inline constexpr std::size_t kSideConfigParams = 4;  // kWheelsPerSide .. kSlipFraction
inline constexpr std::size_t kSideParams = 6;

namespace detail {
// The combiner's limits, in SideParam order: the one table (slip_window's limits depend on the
// read period, side_wheels_range). slip_counts > 0 keeps the threshold positive.
inline constexpr RangeRow kSideRows[kSideParams] = {
    {"wheels_per_side", 1, kMaxWheelsPerSide, ""},
    {"slip_window", 0.0, 10.0, "s"},  // lo, hi: one read .. kMaxSlipWindowReads reads
    {"slip_counts", 0.0, 1e9, "counts", true},
    {"slip_fraction", 0.0, 10.0, ""},
    {"counter_bits", 16, 64, ""},
    {"read_period", 0.0, 1.0, "s", true},
};
}  // namespace detail

// side_wheels_range: the key, allowed range and unit of `k`; slip_window's limits are one read
// and kMaxSlipWindowReads reads of read_period [s].
constexpr RangeRow side_wheels_range(SideParam k, double read_period) noexcept {
  RangeRow r = detail::kSideRows[static_cast<std::size_t>(k)];
  if (k == SideParam::kSlipWindow) {
    r.lo = read_period;
    r.hi = kMaxSlipWindowReads * read_period;
  }
  return r;
}

// side_wheels_value: the value of `k` in `c` (whole numbers as doubles).
constexpr double side_wheels_value(const SideWheelsConfig& c, SideParam k) noexcept {
  switch (k) {
    case SideParam::kWheelsPerSide:
      return c.wheels_per_side;
    case SideParam::kSlipWindow:
      return c.slip_window;
    case SideParam::kSlipCounts:
      return c.slip_counts;
    case SideParam::kSlipFraction:
      return c.slip_fraction;
    case SideParam::kCounterBits:
      return c.counter_bits;
    case SideParam::kReadPeriod:
      break;
  }
  return c.read_period;
}

// side_wheels_outside: the first SideParam of `c` outside its side_wheels_range, or kSideParams
// when every number is within.
constexpr std::size_t side_wheels_outside(const SideWheelsConfig& c) noexcept {
  for (std::size_t i = 0; i < kSideParams; ++i) {
    const auto k = static_cast<SideParam>(i);
    if (!side_wheels_range(k, c.read_period).contains(side_wheels_value(c, k))) return i;
  }
  return kSideParams;
}

// side_wheels_ok: whether check_side_wheels(c) passes, without forming its message (a firmware
// whose configuration is built in carries no text for an error it cannot have: board/).
constexpr bool side_wheels_ok(const SideWheelsConfig& c) noexcept {
  return side_wheels_outside(c) == kSideParams && choice_name(kSideCombineNames, c.combine) != "?";
}

// check_side_wheels: every number in its side_wheels_range (a range error under its key) and the
// combination one of kSideCombineNames.
inline Status check_side_wheels(const SideWheelsConfig& c) {
  if (const std::size_t i = side_wheels_outside(c); i < kSideParams) {
    const auto k = static_cast<SideParam>(i);
    const RangeRow r = side_wheels_range(k, c.read_period);
    return range_error(r.range(r.key, side_wheels_value(c, k)));
  }
  if (choice_name(kSideCombineNames, c.combine) == "?")
    return make_error(Errc::kInvalidArgument,
                      "combine must be " + choice_join(kSideCombineNames, " or "));
  return Ok{};
}

// The combined result of one read of both sides.
struct SideStep {
  std::int64_t left = 0;    // the left side's cumulative count [counts] (EncoderSample.left)
  std::int64_t right = 0;   // the right side's [counts]
  std::uint32_t flags = 0;  // EncoderFlag bits: kEncoderSlipLeft/Right, kEncoderWheelDropped,
                            // kEncoderStaleLeft/Right
  // The within-side spread this read adds to a flagged interval [counts, >= 0]: on the read a
  // side's slip flag rises, the spread of the wheels' window travels (the part of the interval
  // before detection); on later flagged reads, the spread of this read's deltas; 0 unflagged.
  std::int64_t spread_left = 0;
  std::int64_t spread_right = 0;
  // Window spread / threshold of each side (> 1: slip; 0 with fewer than two clean wheels).
  double ratio_left = 0.0;
  double ratio_right = 0.0;
};

// Events of the combiner since start; they only grow (the backend copies them into its
// EncoderCounters: slip_events, wheel_drops; stale_events it adds to its own).
struct SideCounters {
  std::uint64_t slip_events = 0;   // rising edges of kEncoderSlipLeft plus of kEncoderSlipRight
  std::uint64_t wheel_drops = 0;   // wheels going from clean (referenced) to faulted
  std::uint64_t stale_events = 0;  // sides going from live to stale (every wheel faulted)
};

class SideCombiner {
 public:
  // create: validates `c` (check_side_wheels); the combiner holds fixed-size state only.
  static Result<SideCombiner> create(const SideWheelsConfig& c) {
    if (auto s = check_side_wheels(c); !s) return std::move(s).error();
    return SideCombiner(c);
  }
  // make: create() without the error's text (side_wheels_ok): nullopt when `c` is outside it.
  static std::optional<SideCombiner> make(const SideWheelsConfig& c) noexcept {
    if (!side_wheels_ok(c)) return std::nullopt;
    return SideCombiner(c);
  }

  // step: one read of both sides -> the sides' counts and flags; never allocates or throws.
  SideStep step(const SideReadings& left, const SideReadings& right) noexcept {
    SideStep out;
    step_side(0, left, out.left, out.spread_left, out.ratio_left, out.flags);
    step_side(1, right, out.right, out.spread_right, out.ratio_right, out.flags);
    return out;
  }

  const SideCounters& counters() const noexcept { return counters_; }
  const SideWheelsConfig& config() const noexcept { return c_; }
  // window_reads: the slip window in reads.
  int window_reads() const noexcept { return window_; }

 private:
  static constexpr std::int64_t kTwelfths = 12;  // lcm(1, 2, 3, 4)

  // The state of one side.
  struct Side {
    std::array<std::int64_t, kMaxWheelsPerSide> ref{};  // last trusted reading of each wheel
    std::array<std::int64_t, kMaxWheelsPerSide> sum{};  // each wheel's travel over the window
    std::array<int, kMaxWheelsPerSide> clean{};         // consecutive reads with a delta (capped)
    std::array<std::array<std::int32_t, kMaxWheelsPerSide>, kMaxSlipWindowReads> ring{};
    std::uint8_t have_ref = 0;  // bit i: wheel i has a reference
    std::uint8_t faulted = 0;   // the previous read's faulted bits
    std::int64_t acc = 0;       // cumulative count in twelfths
    bool slip = false;          // the slip flag of the previous read
    bool stale = false;         // the stale flag of the previous read
  };

  explicit SideCombiner(const SideWheelsConfig& c) : c_(c) {
    const double reads = c.slip_window / c.read_period;
    window_ = static_cast<int>(reads + 0.5);
    if (window_ < 1) window_ = 1;
    if (window_ > kMaxSlipWindowReads) window_ = kMaxSlipWindowReads;
    mask_ = static_cast<std::uint8_t>((1u << c.wheels_per_side) - 1u);
  }

  // wheel_delta: cur - prev of one wheel's counter, the shortest way round its wrap.
  std::int64_t wheel_delta(std::int64_t prev, std::int64_t cur) const noexcept {
    return wrap_delta(prev, cur, c_.counter_bits);
  }

  // combine: the side's travel this read in twelfths of a count from the n deltas d[0..n-1].
  std::int64_t combine(std::array<std::int64_t, kMaxWheelsPerSide>& d, int n) const noexcept {
    std::int64_t sum = 0;
    for (int i = 0; i < n; ++i) sum += d[i];
    const bool mean = c_.combine == SideCombine::kMean ||
                      (c_.combine == SideCombine::kMedian && n <= 2) || n == 1;
    if (mean) return sum * (kTwelfths / n);
    if (c_.combine == SideCombine::kLeastMagnitude) {
      std::int64_t best = d[0];
      for (int i = 1; i < n; ++i)
        if ((d[i] < 0 ? -d[i] : d[i]) < (best < 0 ? -best : best)) best = d[i];
      return best * kTwelfths;
    }
    // Median of 3 or 4: insertion sort of at most four values.
    for (int i = 1; i < n; ++i)
      for (int j = i; j > 0 && d[j - 1] > d[j]; --j) {
        const std::int64_t t = d[j];
        d[j] = d[j - 1];
        d[j - 1] = t;
      }
    return n == 3 ? d[1] * kTwelfths : (d[1] + d[2]) * (kTwelfths / 2);
  }

  // advance_wheels: each wheel's delta and window bookkeeping; the deltas of the wheels that
  // count this read go to d (n of them), their per-read spread to spread_now.
  int advance_wheels(Side& s, const SideReadings& r, std::array<std::int64_t, kMaxWheelsPerSide>& d,
                     std::int64_t& spread_now, std::uint32_t& dropped) noexcept {
    int n = 0;
    std::int64_t lo = 0, hi = 0;
    const std::uint8_t faulted = r.faulted & mask_;
    for (int i = 0; i < c_.wheels_per_side; ++i) {
      const std::uint8_t bit = static_cast<std::uint8_t>(1u << i);
      std::int64_t delta = 0;
      bool counted = false;
      if (faulted & bit) {
        // An event only for a wheel that was counting: one not yet seen (a controller that
        // has not sent since start) drops out of nothing, here rather than in each backend.
        if (!(s.faulted & bit) && (s.have_ref & bit)) ++counters_.wheel_drops;
        s.clean[i] = 0;
        dropped = kEncoderWheelDropped;
      } else if (!(s.have_ref & bit) || (s.faulted & bit)) {
        s.ref[i] = r.counts[i];  // a (re)gained wheel: its motion while faulted is not added
        s.have_ref |= bit;
        s.clean[i] = 0;
      } else {
        delta = wheel_delta(s.ref[i], r.counts[i]);
        s.ref[i] = r.counts[i];
        counted = true;
        if (s.clean[i] < window_) ++s.clean[i];
      }
      // The window's sums: a per-read delta beyond int32 is no motion any wheel makes (the
      // backend flags such jumps); it is clamped so that the ring stays small.
      constexpr std::int64_t kClamp = 0x7fffffff;
      const std::int32_t stored =
          static_cast<std::int32_t>(delta > kClamp ? kClamp : (delta < -kClamp ? -kClamp : delta));
      std::int32_t& slot = s.ring[static_cast<std::size_t>(head_)][static_cast<std::size_t>(i)];
      s.sum[i] += stored - slot;
      slot = stored;
      if (counted) {
        d[static_cast<std::size_t>(n++)] = delta;
        lo = n == 1 || delta < lo ? delta : lo;
        hi = n == 1 || delta > hi ? delta : hi;
      }
    }
    s.faulted = faulted;
    spread_now = hi - lo;
    return n;
  }

  // slip_ratio: window spread / threshold over the wheels clean for the whole window (0 when
  // fewer than two); `spread` gets the window spread [counts].
  double slip_ratio(const Side& s, std::int64_t& spread) const noexcept {
    int n = 0;
    std::int64_t lo = 0, hi = 0, total = 0;
    for (int i = 0; i < c_.wheels_per_side; ++i) {
      if (s.clean[i] < window_) continue;
      const std::int64_t w = s.sum[i];
      lo = n == 0 || w < lo ? w : lo;
      hi = n == 0 || w > hi ? w : hi;
      total += w;
      ++n;
    }
    spread = hi - lo;
    if (n < 2) return 0.0;
    const double mean = static_cast<double>(total) / n;
    const double threshold = c_.slip_counts + c_.slip_fraction * (mean < 0 ? -mean : mean);
    return static_cast<double>(spread) / threshold;
  }

  void step_side(int side, const SideReadings& r, std::int64_t& count, std::int64_t& spread,
                 double& ratio, std::uint32_t& flags) noexcept {
    Side& s = sides_[side];
    std::array<std::int64_t, kMaxWheelsPerSide> d{};
    std::int64_t spread_now = 0;
    std::uint32_t dropped = 0;
    const int n = advance_wheels(s, r, d, spread_now, dropped);
    if (side == 1) head_ = head_ + 1 == window_ ? 0 : head_ + 1;  // both sides share the slot
    const bool stale = (r.faulted & mask_) == mask_;
    if (n > 0) s.acc += combine(d, n);
    count = floor_div(s.acc + kTwelfths / 2, kTwelfths);
    std::int64_t window_spread = 0;
    ratio = slip_ratio(s, window_spread);
    const bool slip = ratio > 1.0;
    if (slip && !s.slip) ++counters_.slip_events;
    if (stale && !s.stale) ++counters_.stale_events;
    spread = slip ? (s.slip ? spread_now : window_spread) : 0;
    s.slip = slip;
    s.stale = stale;
    const std::uint32_t slip_bit = side == 0 ? kEncoderSlipLeft : kEncoderSlipRight;
    const std::uint32_t stale_bit = side == 0 ? kEncoderStaleLeft : kEncoderStaleRight;
    flags |= (slip ? slip_bit : 0u) | (stale ? stale_bit : 0u) | (stale ? 0u : dropped);
  }

  // floor_div: floor(a / b) for b > 0.
  static constexpr std::int64_t floor_div(std::int64_t a, std::int64_t b) noexcept {
    const std::int64_t q = a / b;
    return q - ((a % b != 0) && (a < 0) ? 1 : 0);
  }

  SideWheelsConfig c_;
  int window_ = 1;         // slip window [reads]
  int head_ = 0;           // ring slot of this read
  std::uint8_t mask_ = 1;  // bits of the configured wheels
  std::array<Side, 2> sides_{};
  SideCounters counters_;
};

}  // namespace odo
