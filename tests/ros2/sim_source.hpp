// A simulated loop for the ROS 2 tests and the latency measurement: a thread ticks at loop_hz,
// stamps each tick with CLOCK_MONOTONIC (the "encoder sample time") and publishes sample k, a
// deterministic function of k, for the bridge's SampleSource to read. A mutex stands in for the
// daemon's triple buffer (the tests check values and timing, not the loop's lock freedom).
#pragma once

#include <time.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <functional>
#include <mutex>
#include <thread>

#include "odo/ros2/mapping.hpp"

namespace odo::ros2::test {

// sample_k: the state published at tick k (any k >= 0); x encodes k exactly (k / 1024).
inline OdomSample sample_k(std::int64_t k, TimeNs t) {
  OdomSample s;
  s.stamp = t;
  const double kd = static_cast<double>(k);
  s.x = kd / 1024.0;
  s.y = -kd / 2048.0;
  s.theta = 0.01 * kd;  // cumulative: passes pi at k = 315, so the wrap is exercised
  const double g = 1.0 + 1e-3 * kd;
  s.pose_cov = {1e-4 * g, 1e-6, 2e-6, 1e-6, 3e-4 * g, 4e-6, 2e-6, 4e-6, 5e-5 * g};
  s.v = 0.25;
  s.omega = 0.5 + 0.001 * static_cast<double>(k % 7);
  s.twist_cov = twist_covariance(TickMotion{0.00024, 0.00026, 0.001, 0.5}, ErrorModelParams{});
  return s;
}

inline TimeNs monotonic_now() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<TimeNs>(ts.tv_sec) * kNsPerSecond + ts.tv_nsec;
}

// sleep_until: CLOCK_MONOTONIC absolute t [ns].
inline void sleep_until(TimeNs t) {
  const timespec ts{static_cast<time_t>(t / kNsPerSecond), static_cast<long>(t % kNsPerSecond)};
  clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr);
}

// LateHook: called on waking for tick k; returns how late [ns] the tick is to be (0: on time),
// as if the loop had woken that much later.
using LateHook = std::function<TimeNs(std::int64_t k)>;

class SimLoop {
 public:
  explicit SimLoop(double loop_hz, LateHook late = {})
      : period_ns_(static_cast<TimeNs>(1e9 / loop_hz)), late_(std::move(late)) {}
  ~SimLoop() { stop(); }
  void start() {
    thread_ = std::thread([this] { run(); });
  }
  void stop() {
    stop_ = true;
    if (thread_.joinable()) thread_.join();
  }
  // read: the bridge's SampleSource.
  bool read(OdomSample& out) {
    std::lock_guard g(m_);
    if (k_ < 0) return false;
    out = latest_;
    return true;
  }

 private:
  void run() {
    const TimeNs t0 = monotonic_now();
    for (std::int64_t k = 0; !stop_; ++k) {
      sleep_until(t0 + (k + 1) * period_ns_);
      if (const TimeNs late = late_ ? late_(k) : 0; late > 0) sleep_until(monotonic_now() + late);
      const OdomSample s = sample_k(k, monotonic_now());
      std::lock_guard g(m_);
      latest_ = s;
      k_ = k;
    }
  }
  TimeNs period_ns_;
  LateHook late_;
  std::atomic<bool> stop_{false};
  std::thread thread_;
  std::mutex m_;
  OdomSample latest_;
  std::int64_t k_ = -1;
};

}  // namespace odo::ros2::test
