// Calibration hand-over into the running loop: the store is read off the loop thread (at start
// and on every SIGHUP); the new Kinematics is passed to the loop thread through a one-slot
// mailbox and applied between two ticks, without locks or allocation on the loop thread.
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <mutex>
#include <optional>
#include <ostream>
#include <string>
#include <thread>

#include "odo/firmware/calibration_store.hpp"
#include "odo/loop/loop.hpp"
#include "odo/odometry/kinematics.hpp"

namespace odo::fw {

// CalibrationHandover: a loop::TickObserver that swaps in offered kinematics on the loop thread and
// stamps loop::LoopSnapshot::calibration_state on every tick.
class CalibrationHandover final : public loop::TickObserver {
 public:
  explicit CalibrationHandover(std::uint8_t state) : state_(state) {}
  // attach: the loop whose kinematics are replaced (configure time).
  void attach(loop::OdometryLoop* loop) noexcept { loop_ = loop; }
  // offer: producer side (one thread). False when the loop has not taken the previous offer
  // before `stop` was set.
  bool offer(const Kinematics& k, std::uint8_t state, const std::atomic<bool>& stop);
  void on_tick(loop::LoopSnapshot& snap) noexcept override;
  // applied: offers the loop has taken so far.
  std::uint64_t applied() const noexcept { return applied_.load(std::memory_order_acquire); }

 private:
  loop::OdometryLoop* loop_ = nullptr;
  std::optional<Kinematics> pending_;  // written only while full_ is false
  std::uint8_t pending_state_ = 0;
  std::atomic<bool> full_{false};
  std::atomic<std::uint64_t> applied_{0};
  std::uint8_t state_;  // loop thread only
};

// read_settled: calls `read` until it gives a store that is not corrupt (state 2), `attempts`
// times at most, and `pause` before each re-read (pause returns false: stop, keep the last
// result). A store read while another process saves to both slots in turn (two saves back to
// back) shows both slots in flight; once the writer is done, a re-read finds the new record.
// `rereads` (optional) receives the number of re-reads.
AppliedCalibration read_settled(const std::function<AppliedCalibration()>& read, int attempts,
                                const std::function<bool()>& pause, int* rereads = nullptr);

// CalibrationReloader: a thread that re-reads the store whenever `request` becomes true.
class CalibrationReloader {
 public:
  CalibrationReloader(CalibrationHandover& h, const KinematicParams& nominal, std::string path,
                      std::string backend, std::ostream& log)
      : handover_(h),
        nominal_(nominal),
        path_(std::move(path)),
        backend_(std::move(backend)),
        log_(log) {}
  ~CalibrationReloader() { stop(); }
  CalibrationReloader(const CalibrationReloader&) = delete;
  CalibrationReloader& operator=(const CalibrationReloader&) = delete;

  // Re-reads of a store found corrupt, and the pause before each [s]: a save to a file or an
  // EEPROM takes milliseconds, an MTD erase block tens of them.
  static constexpr int kReadAttempts = 4;
  static constexpr double kRereadPause = 0.2;

  // start: polls `request` every 50 ms; each time it is set: read (again while the store reads
  // as corrupt, read_settled), apply, log one line.
  void start(std::atomic<bool>& request);
  // stop: ends the thread (idempotent).
  void stop();

 private:
  void reload();

  CalibrationHandover& handover_;
  KinematicParams nominal_;
  std::string path_;
  std::string backend_;
  std::ostream& log_;
  std::thread thread_;
  std::mutex m_;
  std::condition_variable cv_;
  std::atomic<bool> done_{false};
};

}  // namespace odo::fw
