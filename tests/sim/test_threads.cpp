// The firmware's threads together: the loop thread, the status thread reading snapshots through
// the triple buffer, and another thread (later: the CAN receiver) handing set-pose requests to
// the loop. Under ThreadSanitizer (preset tsan) these are the race checks; in every build they
// check that no reader ever sees a torn value.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>

#include <nlohmann/json.hpp>

#include "daemon_text.hpp"
#include "odo/firmware/daemon.hpp"
#include "sim_fixture.hpp"

namespace odo::test {
namespace {

TEST(Threads, SetPoseRequestsAreNeverTorn) {
  // The robot stands still, so the pose changes only through set-pose requests, each of the
  // form (i, -i, i / 1000): a pose that mixes two requests breaks x = -y or theta = x / 1000.
  const auto k = *Kinematics::create(nominal_labmate());
  sim::RobotGeometry g;
  SimRun run(g, k, {});
  std::atomic<bool> stop{false};
  std::thread loop([&] { run.loop->run(0, stop); });
  loop::LoopSnapshot s;
  std::uint64_t changes = 0;  // snapshots showing a newly applied request
  double last_x = 0.0;
  int i = 0;
  int accepted = 0;  // the last request the queue took (a full queue refuses: post() is false)
  // Request until the loop has applied 500 different requests, bounded by time (not by a count
  // of requests: on a loaded machine the loop thread may get no CPU for a while, and a count
  // then runs out before the loop had its chance), so a loop that never applies them fails
  // instead of hanging. The requester yields now and then so that the loop thread gets a core
  // even when only one is free.
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (changes < 500) {
    ++i;
    if ((i & 63) == 0) {
      if (std::chrono::steady_clock::now() > deadline) break;
      std::this_thread::yield();
    }
    const double v = i;
    if (run.loop->post(loop::SetPose{{v, -v, v / 1000.0}})) accepted = i;
    if (run.loop->snapshots().latest(s)) {
      ASSERT_EQ(s.pose.x, -s.pose.y) << "torn set-pose at request " << i;
      ASSERT_EQ(s.pose.theta, s.pose.x / 1000.0) << "torn set-pose at request " << i;
      if (s.pose.x != last_x) ++changes;
      last_x = s.pose.x;
    }
  }
  // Let the loop take the last request, then stop it.
  while (!run.loop->snapshots().latest(s)) std::this_thread::yield();
  const std::uint64_t t0 = s.tick;
  while (run.loop->snapshots().latest(s) && s.tick < t0 + 3) std::this_thread::yield();
  stop = true;
  loop.join();
  EXPECT_EQ(changes, 500u);
  // The last accepted request is the pose (under qemu the requester outruns the loop and fills
  // the 16-command queue, so the very last request may have been refused).
  EXPECT_EQ(run.loop->odometry().pose().x, static_cast<double>(accepted));
  EXPECT_EQ(run.loop->odometry().pose().y, -static_cast<double>(accepted));
}

TEST(Threads, DaemonRealTimeWithStatusThreadStopsOnFlag) {
  // odometryd's own code path in real time: loop thread on CLOCK_MONOTONIC, status thread every
  // 50 ms, stopped from outside through the flag the signal handler sets.
  const std::string cfg = ::testing::TempDir() + "odo_threads.toml";
  std::ofstream(cfg) << "[loop]\nrate_hz = 200\nstatus_period = 0.05\n";
  fw::DaemonOptions o;
  o.config_path = cfg;
  o.json = true;
  std::atomic<bool> stop{false};
  std::ostringstream out;
  LockedText err_text;
  std::ostream err(&err_text);
  int rc = -1;
  std::thread daemon([&] { rc = fw::run_daemon(o, stop, out, err); });
  // At least 2 s of wall time, and on until the status thread has printed 6 lines (0.3 s of
  // running loop), at most 60 s: under qemu-user beside another test the daemon's start-up
  // (config, store, threads) took most of an earlier 0.7 s and the loop ran only 25-32 ticks
  // (armhf, 2026-11-24); a fixed time is only a guess at how long a start takes.
  const auto t0 = std::chrono::steady_clock::now();
  for (auto t = t0; t - t0 < std::chrono::seconds(60); t = std::chrono::steady_clock::now()) {
    if (t - t0 >= std::chrono::seconds(2) && status_lines(err_text.text()) >= 6) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  stop = true;
  daemon.join();
  const std::string e = err_text.text();
  ASSERT_EQ(rc, 0) << e;
  const auto j = nlohmann::json::parse(out.str());
  EXPECT_GT(j["ticks"].get<std::uint64_t>(), 40u);  // >= 0.2 s at 200 Hz even on a busy machine
  EXPECT_GE(status_lines(e), 3u) << e;
}

}  // namespace
}  // namespace odo::test
