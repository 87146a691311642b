// TripleBuffer<T>: hands the newest value from one writer thread to one reader thread without
// locks, without allocation and without data races (each buffer is owned by one side at a time).
// The writer may fill its buffer in place (back(), then publish()) so that a large value is
// written once instead of being built elsewhere and copied.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>

namespace odo::loop {

template <class T>
class TripleBuffer {
 public:
  // back: writer side; the buffer the next publish() hands over. It holds an older value (the
  // one published two or three times before, or T{}): fill every field that changes.
  T& back() noexcept { return bufs_[back_]; }
  // publish: writer side; makes the back buffer the newest value. Wait-free.
  void publish() noexcept {
    newest_ = back_;
    const std::uint8_t prev =
        middle_.exchange(static_cast<std::uint8_t>(back_ | kFresh), std::memory_order_acq_rel);
    back_ = prev & kIndexMask;
  }
  // publish: writer side; makes a copy of `v` the newest value. Wait-free.
  void publish(const T& v) noexcept {
    back() = v;
    publish();
  }
  // newest: writer side; the value last published (T{} before the first publish). The reader
  // may be copying the same buffer, which is safe: neither side writes it until the writer gets
  // it back as its back buffer, and by then a newer value has been published.
  const T& newest() const noexcept { return bufs_[newest_]; }
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
  std::uint8_t back_ = 0;    // writer's buffer
  std::uint8_t newest_ = 1;  // writer side: the buffer last published (the initial middle)
  std::uint8_t front_ = 2;   // reader's buffer
  bool have_ = false;
};

}  // namespace odo::loop
