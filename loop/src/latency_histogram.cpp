#include "odo/loop/latency_histogram.hpp"

#include <algorithm>
#include <cmath>

namespace odo::loop {

void LatencyHistogram::reset() noexcept {
  buckets_.fill(0);
  count_ = 0;
  sum_ = 0;
  max_ = 0;
  min_ = std::numeric_limits<TimeNs>::max();
}

TimeNs LatencyHistogram::upper_bound(std::size_t i) noexcept {
  if (i < static_cast<std::size_t>(kSub)) return static_cast<TimeNs>(i);
  // Block k >= 1 holds [2^e, 2^(e+1)) with e = k + kSubBits - 1, in kSub buckets of 2^(e-kSubBits).
  const auto block = static_cast<int>(i / kSub);
  const auto sub = static_cast<std::int64_t>(i % kSub);
  const int shift = block - 1;  // e - kSubBits
  const std::int64_t lower = (kSub + sub) << shift;
  return lower + (std::int64_t{1} << shift) - 1;
}

namespace {
// rank_of: 1-based rank of the q-quantile among n values: the ceil(q * n)-th smallest, >= 1.
std::uint64_t rank_of(double q, std::uint64_t n) noexcept {
  q = std::clamp(q, 0.0, 1.0);
  return std::max<std::uint64_t>(1,
                                 static_cast<std::uint64_t>(std::ceil(q * static_cast<double>(n))));
}
}  // namespace

TimeNs LatencyHistogram::percentile(double q) const noexcept {
  if (count_ == 0) return 0;
  const std::uint64_t rank = rank_of(q, count_);
  std::uint64_t seen = 0;
  for (std::size_t i = 0; i < kBuckets; ++i) {
    seen += buckets_[i];
    if (seen >= rank) return std::clamp(upper_bound(i), min_, max_);
  }
  return max_;
}

TimingSummary LatencyHistogram::summary() const noexcept {
  TimingSummary s;
  s.count = count_;
  if (count_ == 0) return s;
  s.min = min_;
  s.max = max_;
  s.mean = sum_ / static_cast<TimeNs>(count_);
  // One walk for both percentiles; it stops at the p99.9 bucket, usually far below the end.
  const std::uint64_t r99 = rank_of(0.99, count_);
  const std::uint64_t r999 = rank_of(0.999, count_);
  std::uint64_t seen = 0;
  s.p99 = s.p999 = max_;
  bool have99 = false;
  for (std::size_t i = 0; i < kBuckets; ++i) {
    seen += buckets_[i];
    if (!have99 && seen >= r99) {
      s.p99 = std::clamp(upper_bound(i), min_, max_);
      have99 = true;
    }
    if (seen >= r999) {
      s.p999 = std::clamp(upper_bound(i), min_, max_);
      break;
    }
  }
  return s;
}

}  // namespace odo::loop
