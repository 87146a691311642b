// Commands into the running loop: the one way another thread or an observer changes the loop's
// state. post() from any thread; the loop applies everything queued at the top of its next
// tick, in the order posted, before that tick's motion is added. New kinds of command (absolute
// position fixes, gyro settings) are new alternatives of Command.
#pragma once

#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <type_traits>
#include <variant>

#include "odo/calibration/store.hpp"
#include "odo/odometry/kinematics.hpp"
#include "odo/odometry/pose.hpp"

namespace odo::loop {

// SetPose: replace the pose; its covariance becomes zero (a set pose is taken as exact). The
// type is odometry's (odo::SetPose), which protocol/ and ros2/ also see: one type, no copies.
using odo::SetPose;

// SetKinematics: new calibrated kinematics (e.g. re-read on SIGHUP) and the store's status they
// came from; the next tick integrates with them, the pose is kept.
struct SetKinematics {
  Kinematics kinematics;
  calib::StoreStatus calibration = calib::StoreStatus::kUncalibrated;
};

using Command = std::variant<SetPose, SetKinematics>;
static_assert(std::is_trivially_copyable_v<Command>,
              "commands are copied through a lock-free ring");

// CommandQueue: bounded multi-producer single-consumer queue, allocated inside the object (no
// heap), lock-free for the consumer (the loop thread never waits). A slot's sequence number
// says whose turn it is (Vyukov's bounded queue): a producer claims a position with one
// compare-and-swap and publishes the command with a release store of the slot's sequence.
class CommandQueue {
 public:
  static constexpr std::size_t kCapacity = 16;  // power of two

  CommandQueue() noexcept {
    for (std::size_t i = 0; i < kCapacity; ++i) slots_[i].seq.store(i, std::memory_order_relaxed);
  }
  CommandQueue(const CommandQueue&) = delete;
  CommandQueue& operator=(const CommandQueue&) = delete;

  // post: any thread; false (and nothing queued) when kCapacity commands are waiting.
  bool post(const Command& c) noexcept {
    std::size_t pos = head_.load(std::memory_order_relaxed);
    for (;;) {
      Slot& s = slots_[pos & (kCapacity - 1)];
      const std::size_t seq = s.seq.load(std::memory_order_acquire);
      const auto diff = static_cast<std::ptrdiff_t>(seq) - static_cast<std::ptrdiff_t>(pos);
      if (diff == 0) {
        if (head_.compare_exchange_weak(pos, pos + 1, std::memory_order_relaxed)) {
          s.cmd = c;
          s.seq.store(pos + 1, std::memory_order_release);
          return true;
        }
      } else if (diff < 0) {
        return false;  // full
      } else {
        pos = head_.load(std::memory_order_relaxed);
      }
    }
  }

  // drain: consumer thread only; calls apply(const Command&) for every command published so far,
  // oldest first; returns how many.
  template <class Apply>
  std::size_t drain(Apply&& apply) noexcept {
    std::size_t n = 0;
    for (;;) {
      Slot& s = slots_[tail_ & (kCapacity - 1)];
      if (s.seq.load(std::memory_order_acquire) != tail_ + 1) return n;
      apply(static_cast<const Command&>(s.cmd));
      s.seq.store(tail_ + kCapacity, std::memory_order_release);
      ++tail_;
      ++n;
    }
  }

  // empty: consumer thread only; true when nothing is waiting (one acquire load).
  bool empty() const noexcept {
    return slots_[tail_ & (kCapacity - 1)].seq.load(std::memory_order_acquire) != tail_ + 1;
  }

 private:
  struct Slot {
    std::atomic<std::size_t> seq{0};
    Command cmd{SetPose{}};
  };
  std::array<Slot, kCapacity> slots_;
  alignas(64) std::atomic<std::size_t> head_{0};  // next position to claim (producers)
  alignas(64) std::size_t tail_ = 0;              // next position to take (consumer)
};

}  // namespace odo::loop
