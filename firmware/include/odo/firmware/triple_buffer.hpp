// TripleBuffer<T>: hands the newest value from one writer thread to one reader thread without
// locks, without allocation and without data races (each buffer is owned by one side at a time).
#pragma once

#include <array>
#include <atomic>
#include <cstdint>

namespace odo::fw {

template <class T>
class TripleBuffer {
 public:
  // publish: writer side; makes `v` the newest value. Wait-free.
  void publish(const T& v) noexcept {
    bufs_[back_] = v;
    const std::uint8_t prev =
        middle_.exchange(static_cast<std::uint8_t>(back_ | kFresh), std::memory_order_acq_rel);
    back_ = prev & kIndexMask;
  }
  // latest: reader side; copies the newest published value into `out`; false if none yet.
  bool latest(T& out) noexcept {
    if (middle_.load(std::memory_order_acquire) & kFresh) {
      const std::uint8_t prev = middle_.exchange(front_, std::memory_order_acq_rel);
      front_ = prev & kIndexMask;
      have_ = true;
    }
    if (have_) out = bufs_[front_];
    return have_;
  }

 private:
  static constexpr std::uint8_t kFresh = 0x4;
  static constexpr std::uint8_t kIndexMask = 0x3;
  std::array<T, 3> bufs_{};
  std::atomic<std::uint8_t> middle_{1};
  std::uint8_t back_ = 0;   // writer's buffer
  std::uint8_t front_ = 2;  // reader's buffer
  bool have_ = false;
};

}  // namespace odo::fw
