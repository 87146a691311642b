#include "odo/firmware/calibration_reload.hpp"

#include <chrono>
#include <string>

#include "odo/firmware/calibration_store.hpp"

namespace odo::fw {

void CalibrationReloader::start(std::atomic<bool>& request) {
  thread_ = std::thread([this, &request] {
    std::unique_lock lk(m_);
    while (!done_.load()) {
      cv_.wait_for(lk, std::chrono::milliseconds(50));
      if (request.exchange(false)) {
        // Without the lock: stop() must be able to set done_ while a reload pauses between
        // reads or waits for a loop that no longer ticks to take its offer.
        lk.unlock();
        reload();
        lk.lock();
      }
    }
  });
}

void CalibrationReloader::stop() {
  {
    std::lock_guard lk(m_);
    done_.store(true);
  }
  cv_.notify_all();
  if (thread_.joinable()) thread_.join();
}

AppliedCalibration read_settled(const std::function<AppliedCalibration()>& read, int attempts,
                                const std::function<bool()>& pause, int* rereads) {
  AppliedCalibration a = read();
  int n = 0;
  while (a.state == calib::StoreStatus::kCorrupt && n + 1 < attempts && pause()) {
    ++n;
    a = read();
  }
  if (rereads != nullptr) *rereads = n;
  return a;
}

void CalibrationReloader::reload() {
  int rereads = 0;
  AppliedCalibration a =
      read_settled([this] { return read_and_apply(nominal_, path_, backend_); }, kReadAttempts,
                   [this] {
                     // Sleep in short steps so that stop() is not held up by a corrupt store.
                     const auto until = std::chrono::steady_clock::now() +
                                        std::chrono::duration<double>(kRereadPause);
                     while (std::chrono::steady_clock::now() < until) {
                       if (done_.load()) return false;
                       std::this_thread::sleep_for(std::chrono::milliseconds(10));
                     }
                     return true;
                   },
                   &rereads);
  if (rereads > 0) {
    a.report +=
        "; read " + std::to_string(rereads + 1) + " times (" +
        (a.state == calib::StoreStatus::kCorrupt ? "corrupt every time"
                                                 : "corrupt at first: a save was in flight") +
        ")";
  }
  auto k = Kinematics::create(a.params);
  if (!k) {
    // apply_calibration only returns parameters Kinematics accepted; keep the running ones.
    log_ << "odometryd: SIGHUP: " << k.error().message << "; calibration unchanged\n";
    return;
  }
  // One string per line so that the status thread's lines do not interleave with it.
  const std::string line = "odometryd: SIGHUP: " + a.report + "\n";
  log_ << line << std::flush;
  // A full queue (a loop that stopped ticking) is waited for until stop().
  while (!commands_.post(loop::SetKinematics{*k, a.state})) {
    if (done_.load()) return;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
}

}  // namespace odo::fw
