#include "odo/firmware/calibration_reload.hpp"

#include <chrono>

#include "odo/firmware/calibration_io.hpp"

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

void CalibrationHandover::on_tick(LoopSnapshot& snap) noexcept {
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
      if (request.exchange(false)) reload();
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

void CalibrationReloader::reload() {
  AppliedCalibration a = read_and_apply(nominal_, path_, backend_);
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
