// LatencyHistogram: a fixed-size log-linear histogram of non-negative durations [ns], recorded
// on the loop path without allocation or locks. Exact below 32 ns; above, 32 sub-buckets per
// power of two, so a reported percentile is at most 1/32 (3.1 %) above the true value.
#pragma once

#include <array>
#include <cstdint>
#include <limits>

#include "odo/hal/time.hpp"

namespace odo::loop {

// Summary of one histogram [ns]; all zero while count == 0.
struct TimingSummary {
  std::uint64_t count = 0;
  TimeNs min = 0;
  TimeNs mean = 0;
  TimeNs p99 = 0;   // upper bound of the bucket holding the 99th percentile (clamped to max)
  TimeNs p999 = 0;  // same for the 99.9th percentile
  TimeNs max = 0;
};

class LatencyHistogram {
 public:
  static constexpr int kSubBits = 5;  // 32 sub-buckets per octave
  static constexpr int kSub = 1 << kSubBits;
  static constexpr int kMaxExponent = 40;  // values up to 2^40 ns (18 min); larger are clamped
  static constexpr std::size_t kBuckets =
      static_cast<std::size_t>((kMaxExponent - kSubBits + 2) * kSub);

  // record: adds one value [ns]; negative values count as 0. Wait-free, about 15 instructions.
  void record(TimeNs v) noexcept {
    if (v < 0) v = 0;
    ++buckets_[index(v)];
    ++count_;
    sum_ += v;
    if (v > max_) max_ = v;
    if (v < min_) min_ = v;
  }
  // reset: forgets every value.
  void reset() noexcept;
  std::uint64_t count() const noexcept { return count_; }
  // percentile: smallest bucket upper bound [ns] below or at which a fraction q (0..1] of the
  // values lie, clamped to [min, max]; 0 when empty. Walks the buckets: not for every tick.
  TimeNs percentile(double q) const noexcept;
  // summary: min, mean, p99, p99.9, max [ns].
  TimingSummary summary() const noexcept;

  // index: bucket of value v >= 0 (public for tests).
  static std::size_t index(TimeNs v) noexcept {
    const auto u = static_cast<std::uint64_t>(v);
    if (u < static_cast<std::uint64_t>(kSub)) return static_cast<std::size_t>(u);
    int e = 63 - __builtin_clzll(u);  // floor(log2 u) >= kSubBits
    if (e > kMaxExponent) return kBuckets - 1;
    const auto sub = static_cast<std::size_t>((u >> (e - kSubBits)) & (kSub - 1));
    return static_cast<std::size_t>(e - kSubBits + 1) * kSub + sub;
  }
  // upper_bound: largest value [ns] that falls into bucket i.
  static TimeNs upper_bound(std::size_t i) noexcept;

 private:
  std::array<std::uint64_t, kBuckets> buckets_{};  // 64-bit: no wrap in a long run
  std::uint64_t count_ = 0;
  TimeNs sum_ = 0;
  TimeNs max_ = 0;
  TimeNs min_ = std::numeric_limits<TimeNs>::max();
};

}  // namespace odo::loop
