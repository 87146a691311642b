// CanLogWriter (--can-log): the frames the broadcaster sent, written to a candump -L file by a
// thread of its own (the log writer thread, the only thread of this file), so the loop never
// does file I/O. README "CAN protocol" documents the log.
#pragma once

#include <atomic>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "odo/hal/can_bus.hpp"
#include "odo/hal/result.hpp"
#include "odo/loop/spsc_ring.hpp"

namespace odo::fw {

// CanFrameRing: the loop thread's frames to the log thread, allocated once; a full ring drops
// the frame and counts it.
using CanFrameRing = loop::SpscRing<CanFrame>;
inline constexpr std::size_t kCanLogRingFrames = 4096;  // 24 s of the default broadcast

// CanLogWriter: drains a CanFrameRing into a candump -L file from its own thread (every 20 ms),
// so the loop never does file I/O, and flushes after each drain: the file is at most ~20 ms
// behind the loop, in whole lines. Frame stamps are loop time [ns]; the wall-clock time of loop
// time zero is added.
class CanLogWriter {
 public:
  ~CanLogWriter();
  static Result<std::unique_ptr<CanLogWriter>> open(const std::string& path, std::string iface);
  CanFrameRing& ring() noexcept { return ring_; }
  // start: the thread; epoch_ns = CLOCK_REALTIME at loop time zero [ns].
  void start(std::int64_t epoch_ns);
  // stop: joins the thread after writing everything queued; closes the file.
  void stop();
  // written: lines written so far; safe to read from any thread while the writer runs.
  std::uint64_t written() const noexcept { return written_.load(std::memory_order_relaxed); }

 private:
  CanLogWriter(std::FILE* f, std::string iface) : file_(f), iface_(std::move(iface)) {}
  void drain() noexcept;
  std::FILE* file_;
  std::vector<char> buffer_;  // stdio buffer, allocated at open: fwrite never allocates
  std::string iface_;
  CanFrameRing ring_{kCanLogRingFrames};
  std::int64_t epoch_ns_ = 0;
  std::atomic<bool> stop_{false};
  std::thread thread_;
  // Atomic: the writer thread counts, the status side may read while it runs (a plain
  // counter was only safe to read after stop(); ThreadSanitizer found the mid-run read).
  std::atomic<std::uint64_t> written_{0};
};

}  // namespace odo::fw
