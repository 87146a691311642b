// SpscRing: a bounded single-producer single-consumer ring of trivially copyable values,
// allocated once at configure time; push and pop never allocate, lock or wait. A full ring
// drops the value and counts it. Carries the self-calibration record (count segments, fixes)
// from the loop thread to the estimator thread, and the CAN frames to the candump log writer.
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <type_traits>
#include <vector>

namespace odo::loop {

template <class T>
class SpscRing {
  static_assert(std::is_trivially_copyable_v<T>, "values are copied into preallocated slots");

 public:
  // capacity_pow2: rounded up to a power of two (at least 2).
  explicit SpscRing(std::size_t capacity_pow2) {
    std::size_t n = 2;
    while (n < capacity_pow2) n *= 2;
    buf_.resize(n);
    mask_ = n - 1;
  }
  SpscRing(const SpscRing&) = delete;
  SpscRing& operator=(const SpscRing&) = delete;

  // push: producer thread; false (and counted in dropped()) when full.
  bool push(const T& v) noexcept {
    const std::uint64_t h = head_.load(std::memory_order_relaxed);
    if (h - tail_.load(std::memory_order_acquire) > mask_) {
      dropped_.fetch_add(1, std::memory_order_relaxed);
      return false;
    }
    slot(h) = v;
    head_.store(h + 1, std::memory_order_release);
    return true;
  }
  // push_wait: producer thread in virtual time only (no deadlines to keep): calls wait() until
  // there is space, so a run faster than real time loses no value. The caller says how to wait
  // (a thread's yield on Linux): the ring itself knows no threads.
  template <class Wait>
  void push_wait(const T& v, Wait&& wait) noexcept {
    while (head_.load(std::memory_order_relaxed) - tail_.load(std::memory_order_acquire) > mask_)
      wait();
    push(v);
  }
  // pop: consumer thread; false when empty.
  bool pop(T& out) noexcept {
    const std::uint64_t t = tail_.load(std::memory_order_relaxed);
    if (t == head_.load(std::memory_order_acquire)) return false;
    out = slot(t);
    tail_.store(t + 1, std::memory_order_release);
    return true;
  }
  std::size_t capacity() const noexcept { return mask_ + 1; }
  // dropped: values lost to a full ring, any thread.
  std::uint64_t dropped() const noexcept { return dropped_.load(std::memory_order_relaxed); }

 private:
  // slot: the value of running index i. The 64-bit indices never wrap in practice; the masked
  // index is below the capacity, which is a size_t, so the narrowing on 32-bit targets is exact.
  T& slot(std::uint64_t i) noexcept { return buf_[static_cast<std::size_t>(i & mask_)]; }

  std::vector<T> buf_;
  std::size_t mask_ = 0;
  alignas(64) std::atomic<std::uint64_t> head_{0};  // next write (producer)
  alignas(64) std::atomic<std::uint64_t> tail_{0};  // next read (consumer)
  std::atomic<std::uint64_t> dropped_{0};
};

}  // namespace odo::loop
