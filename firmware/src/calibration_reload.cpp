#include "odo/firmware/calibration_reload.hpp"

#include <chrono>
#include <string>

#include "odo/firmware/calibration_store.hpp"

namespace odo::fw {

bool CalibrationHandover::offer(const Kinematics& k, std::uint8_t state,
                                const std::atomic<bool>& stop) {
  // Wait until the loop has taken the previous offer: the slot is ours only while empty.
  while (full_.load(std::memory_order_acquire)) {
    if (stop.load()) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  pending_ = k;
  pending_state_ = state;
  full_.store(true, std::memory_order_release);
  return true;
}

void CalibrationHandover::on_tick(loop::LoopSnapshot& snap) noexcept {
  if (full_.load(std::memory_order_acquire)) {
    // Between two ticks: the next tick integrates with the new factors.
    if (loop_ != nullptr && pending_) loop_->set_kinematics(*pending_);
    state_ = pending_state_;
    full_.store(false, std::memory_order_release);
    applied_.fetch_add(1, std::memory_order_acq_rel);
  }
  snap.calibration_state = state_;
}

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
  while (a.state == 2 && n + 1 < attempts && pause()) {
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
    a.report += "; read " + std::to_string(rereads + 1) + " times (" +
                (a.state == 2 ? "corrupt every time" : "corrupt at first: a save was in flight") +
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
  handover_.offer(*k, a.state, done_);
}

}  // namespace odo::fw
