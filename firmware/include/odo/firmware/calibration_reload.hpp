// Calibration reload into the running loop: the store is read off the loop thread (on every
// SIGHUP); the new Kinematics and the store's status are posted to the loop as a SetKinematics
// command and applied at the top of the next tick, without locks or allocation on the loop
// thread.
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
#include "odo/loop/command.hpp"
#include "odo/odometry/kinematics.hpp"

namespace odo::fw {

// read_settled: calls `read` until it gives a store that is not corrupt, `attempts`
// times at most, and `pause` before each re-read (pause returns false: stop, keep the last
// result). A store read while another process saves to both slots in turn (two saves back to
// back) shows both slots in flight; once the writer is done, a re-read finds the new record.
// `rereads` (optional) receives the number of re-reads.
AppliedCalibration read_settled(const std::function<AppliedCalibration()>& read, int attempts,
                                const std::function<bool()>& pause, int* rereads = nullptr);

// CalibrationReloader: a thread that re-reads the store whenever `request` becomes true.
class CalibrationReloader {
 public:
  // commands: the loop's inbound queue (OdometryLoop::commands()).
  CalibrationReloader(loop::CommandQueue& commands, const KinematicParams& nominal,
                      std::string path, NvBackend backend, std::ostream& log)
      : commands_(commands),
        nominal_(nominal),
        path_(std::move(path)),
        backend_(backend),
        log_(log) {}
  ~CalibrationReloader() { stop(); }
  CalibrationReloader(const CalibrationReloader&) = delete;
  CalibrationReloader& operator=(const CalibrationReloader&) = delete;

  // Re-reads of a store found corrupt, and the pause before each [s]: a save to a file or an
  // EEPROM takes milliseconds, an MTD erase block tens of them.
  static constexpr int kReadAttempts = 4;
  static constexpr double kRereadPause = 0.2;

  // start: polls `request` every 50 ms; each time it is set: read (again while the store reads
  // as corrupt, read_settled), log one line, post the kinematics (waiting while the queue is
  // full, until stop()).
  void start(std::atomic<bool>& request);
  // stop: ends the thread (idempotent).
  void stop();

 private:
  void reload();

  loop::CommandQueue& commands_;
  KinematicParams nominal_;
  std::string path_;
  NvBackend backend_;
  std::ostream& log_;
  std::thread thread_;
  std::mutex m_;
  std::condition_variable cv_;
  std::atomic<bool> done_{false};
};

}  // namespace odo::fw
