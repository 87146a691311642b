// The bridge on the loopback, received by two other programs: an independent Fast DDS peer
// (types from fastddsgen) and a Cyclone DDS peer (a separate process). Each decodes rt/odom and
// rt/tf into the values the simulated loop published, and publishes a set_pose that the bridge
// hands to its sink. DDS is confined to 127.0.0.1 (no multicast, unicast discovery), on a domain
// chosen from the process id so that parallel runs do not meet.
#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <mutex>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "odo/ros2/bridge.hpp"
#include "peer_run.hpp"
#include "sim_source.hpp"
#include "tsan_suppressions.hpp"

namespace odo::ros2 {
namespace {

using test::PeerRun;
using test::run_peer;
using test::sample_k;
using test::split;

TimeNs realtime_now() {
  timespec ts{};
  clock_gettime(CLOCK_REALTIME, &ts);
  return static_cast<TimeNs>(ts.tv_sec) * kNsPerSecond + ts.tv_nsec;
}

constexpr int kOdom = 20;  // messages each peer waits for

// loopback_config: the bridge on 127.0.0.1 only (no multicast, unicast discovery) on domain,
// publishing at rate_hz.
Config loopback_config(int domain, double rate_hz) {
  Config c;
  c.enabled = true;
  c.domain_id = static_cast<std::uint32_t>(domain);
  c.rate_hz = rate_hz;
  c.interfaces = {"lo"};
  c.multicast = false;
  c.peers = {"127.0.0.1"};
  return c;
}

class Ros2Loopback : public ::testing::Test {
 protected:
  // run: bridge (100 Hz, tf on, namespace ns) fed by a 1 kHz simulated loop; the peer at path
  // receives kOdom odom and tf messages and publishes set_pose (1.5, -2.5, 0.7, variance 0.01).
  void run(const std::string& peer, const std::string& ns, int domain) {
    Config c = loopback_config(domain, 100);
    c.ns = ns;
    test::SimLoop loop(1000);
    auto b = Bridge::create(
        c, 1000, [&](OdomSample& s) { return loop.read(s); },
        [&](const PoseWithCovarianceFields& p) {
          std::lock_guard g(m_);
          set_poses_.push_back(p);
        });
    ASSERT_TRUE(b.ok()) << b.error().message;
    loop.start();
    start_ = realtime_now();
    ASSERT_TRUE((*b)->start().ok());
    std::string cmd = peer + " --domain " + std::to_string(domain) + " --odom " +
                      std::to_string(kOdom) + " --tf " + std::to_string(kOdom) +
                      " --set-pose 1.5 -2.5 0.7 0.01 --timeout 30";
    if (!ns.empty()) cmd += " --ns " + ns;
    run_ = run_peer(cmd);
    // The peer exits once the bridge's reader acknowledged its set_pose; the bridge takes it at
    // its next tick (10 ms): give it up to 2 s before stopping.
    for (int i = 0; i < 200 && (*b)->stats().set_pose_received == 0; ++i) {
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    (*b)->stop();
    loop.stop();
    stats_ = (*b)->stats();
  }

  void check_odom(const std::vector<std::string>& t) {
    ASSERT_EQ(t.size(), 6u + 7 + 36 + 6 + 36);
    const TimeNs stamp = std::stoll(t[1]) * kNsPerSecond + std::stoll(t[2]);
    const TimeNs recv = std::stoll(t[3]);
    // The stamp is the sample time in system time: after the test started, before receipt,
    // and (a 1 kHz loop read at 100 Hz on loopback) well under 1 s old.
    EXPECT_GE(stamp, start_ - 2'000'000);
    EXPECT_LE(stamp, recv);
    EXPECT_LT(recv - stamp, kNsPerSecond);
    EXPECT_EQ(t[4], "odom");
    EXPECT_EQ(t[5], "base_link");
    std::vector<double> v;
    for (std::size_t i = 6; i < t.size(); ++i) v.push_back(std::strtod(t[i].c_str(), nullptr));
    const std::int64_t k = std::llround(v[0] * 1024.0);
    const OdomSample s = sample_k(k, 0);
    auto f = odometry_fields(s, 0);
    ASSERT_TRUE(f.ok());
    // Every decoded double equals what the mapping made of sample k, bit for bit.
    const double pose[] = {
        f->x, f->y, f->z, f->orientation.x, f->orientation.y, f->orientation.z, f->orientation.w};
    for (int i = 0; i < 7; ++i) EXPECT_EQ(v[i], pose[i]) << "pose field " << i << " k " << k;
    for (int i = 0; i < 36; ++i) EXPECT_EQ(v[7 + i], f->pose_cov[i]) << "pose cov " << i;
    const double tw[] = {f->vx, f->vy, f->vz, f->wx, f->wy, f->wz};
    for (int i = 0; i < 6; ++i) EXPECT_EQ(v[43 + i], tw[i]) << "twist " << i;
    for (int i = 0; i < 36; ++i) EXPECT_EQ(v[49 + i], f->twist_cov[i]) << "twist cov " << i;
    // And a few against the sample directly (not through the mapping).
    EXPECT_EQ(v[1], s.y);
    EXPECT_EQ(v[7 + 35], s.pose_cov[8]);  // yaw variance at [35]
    EXPECT_EQ(v[7 + 5], s.pose_cov[2]);   // x-yaw at [5]
    EXPECT_EQ(v[43], s.v);
    EXPECT_EQ(v[48], s.omega);
    EXPECT_NEAR(v[5], std::sin(0.5 * std::remainder(s.theta, 2 * M_PI)), 1e-12);
  }

  void check_tf(const std::vector<std::string>& t) {
    ASSERT_EQ(t.size(), 6u + 7);
    EXPECT_EQ(t[4], "odom");
    EXPECT_EQ(t[5], "base_link");
    const double x = std::strtod(t[6].c_str(), nullptr);
    const OdomSample s = sample_k(std::llround(x * 1024.0), 0);
    const Quaternion q = quaternion_from_yaw(s.theta);
    EXPECT_EQ(std::strtod(t[7].c_str(), nullptr), s.y);
    EXPECT_EQ(std::strtod(t[8].c_str(), nullptr), 0.0);
    EXPECT_EQ(std::strtod(t[11].c_str(), nullptr), q.z);
    EXPECT_EQ(std::strtod(t[12].c_str(), nullptr), q.w);
  }

  void check_all() {
    ASSERT_EQ(run_.status, 0) << "peer failed; last line: "
                              << (run_.lines.empty() ? "" : run_.lines.back());
    int odom = 0, tf = 0;
    for (const auto& l : run_.lines) {
      const auto t = split(l);
      if (t.empty()) continue;
      if (t[0] == "odom") {
        ++odom;
        check_odom(t);
      } else if (t[0] == "tf") {
        ++tf;
        check_tf(t);
      }
    }
    EXPECT_GE(odom, kOdom);
    EXPECT_GE(tf, kOdom);
    EXPECT_GE(stats_.odom_published, static_cast<std::uint64_t>(kOdom));
    EXPECT_EQ(stats_.write_errors, 0u);
    EXPECT_EQ(stats_.set_pose_rejected, 0u);
    std::lock_guard g(m_);
    ASSERT_FALSE(set_poses_.empty()) << "no set_pose reached the sink";
    EXPECT_EQ(stats_.set_pose_received, set_poses_.size());
    for (const PoseWithCovarianceFields& p : set_poses_) {
      EXPECT_EQ(p.set_pose.pose.x, 1.5);
      EXPECT_EQ(p.set_pose.pose.y, -2.5);
      EXPECT_NEAR(p.set_pose.pose.theta, 0.7, 1e-12);
      EXPECT_EQ(p.cov[0], 0.01);
      EXPECT_EQ(p.cov[4], 0.01);
      EXPECT_EQ(p.cov[8], 0.01);
      EXPECT_EQ(p.cov[1], 0.0);
    }
  }

  PeerRun run_;
  BridgeStats stats_;
  TimeNs start_ = 0;
  std::mutex m_;
  std::vector<PoseWithCovarianceFields> set_poses_;
};

int test_domain(int offset) {
  return test::test_domain(offset, static_cast<int>(getpid()));
}

// Native builds only (tests/ros2/CMakeLists.txt: Fast DDS under qemu-user received nothing).
#if ODO_FASTDDS_INTEROP
TEST_F(Ros2Loopback, FastDdsPeerDecodesOdomAndTfAndSendsSetPose) {
  const std::string peer = ODO_FASTDDS_PEER;
  if (peer.empty()) {
    GTEST_SKIP() << "Fast DDS peer not built: libfastrtps-dev and fastddsgen (tools/setup.sh "
                    "--tests) are needed";
  }
  run(test::fastdds_peer_env() + peer, "/robot7", test_domain(0));
  check_all();
}
#endif

TEST_F(Ros2Loopback, CyclonePeerDecodesOdomAndTfAndSendsSetPose) {
  // The peer takes its network set-up from CYCLONEDDS_URI: loopback, unicast discovery.
  setenv("CYCLONEDDS_URI", test::kCycloneLoopbackXml, 1);
  const std::string emulator = ODO_PEER_EMULATOR;
  run(emulator.empty() ? ODO_CYCLONE_PEER : emulator + " " + ODO_CYCLONE_PEER, "", test_domain(1));
  check_all();
}

TEST(Ros2Bridge, PublishesEachSampleOnceAndStopsWithoutWaitingForItsPeriod) {
  // A source that always returns the same sample, stamped 1 ns (not a CLOCK_MONOTONIC phase
  // the bridge could lock to): one write of odom and tf, then the free-running fallback waits a
  // whole period (rate 0.5 Hz: 2 s) before it reads again, and stop() must not wait for it.
  // stop() reads once more and does not write the same sample twice.
  const Config c = loopback_config(test_domain(2), 0.5);
  int calls = 0;
  auto b = Bridge::create(
      c, 1000,
      [&](OdomSample& s) {
        ++calls;
        s = sample_k(3, 1);
        return true;
      },
      nullptr);
  ASSERT_TRUE(b.ok()) << b.error().message;
  ASSERT_TRUE((*b)->start().ok());
  EXPECT_FALSE((*b)->start().ok());  // already running
  std::this_thread::sleep_for(std::chrono::milliseconds(1100));
  const auto t0 = std::chrono::steady_clock::now();
  (*b)->stop();
  const auto stop_ms =
      std::chrono::duration_cast<std::chrono::milliseconds>(std::chrono::steady_clock::now() - t0)
          .count();
  EXPECT_LT(stop_ms, 200);
  const BridgeStats st = (*b)->stats();
  EXPECT_EQ(st.odom_published, 1u);
  EXPECT_EQ(st.tf_published, 1u);
  // Read at t = 0 and once more when stopped (the final sample goes out before the thread
  // ends); the read in between would have been at t = 2 s. The last read found the sample
  // already published.
  EXPECT_EQ(calls, 2);
  EXPECT_EQ(st.unchanged_skipped, 1u);
  (*b)->stop();  // idempotent
}

TEST(Ros2Bridge, EarlyWakeUpKeepsTheRateAndStillSendsTheLastSampleAtStop) {
  // spin_us = 500 at 100 Hz from a 1 kHz loop: the thread wakes 0.5 ms before each due tick
  // and polls the buffer for that tick's sample. It must still write at the configured rate
  // (one tick in ten, not every tick it sees while polling), nearly every write after the first
  // must have gone through the poll, and once the loop stopped its final sample must go out
  // (the poll gives up, stop() reads once more).
  Config c = loopback_config(test_domain(3), 100);
  c.spin_us = 500;
  test::SimLoop loop(1000);
  auto b = Bridge::create(
      c, 1000, [&](OdomSample& s) { return loop.read(s); }, nullptr);
  ASSERT_TRUE(b.ok()) << b.error().message;
  loop.start();
  const auto t0 = std::chrono::steady_clock::now();
  ASSERT_TRUE((*b)->start().ok());
  std::this_thread::sleep_for(std::chrono::milliseconds(1000));
  loop.stop();
  const double ran_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  OdomSample final_sample;
  ASSERT_TRUE(loop.read(final_sample));
  (*b)->stop();
  const BridgeStats st = (*b)->stats();
  // At most one write per 10 ms of running, plus the first and the final one; at least 60 %
  // of the rate (the thread may be starved on a loaded machine, and skips rather than bursts).
  EXPECT_LE(st.odom_published, static_cast<std::uint64_t>(ran_s * 100) + 2) << ran_s << " s";
  EXPECT_GE(st.odom_published, 60u);
  EXPECT_EQ(st.tf_published, st.odom_published);
  // Every write but the last (after stop) is counted in one way it went out: after the poll, for
  // the due tick without a poll (the thread woke late, or waited for a tick the simulated loop
  // made late), in place of a tick that never came, or with no due tick (the first, and after a
  // wake-up the thread missed). Before, the late wake-ups were not counted and at most 10 were
  // allowed: red in a fresh-chroot CI run on a machine loaded beside it (13). How many go
  // through the poll is the scheduler's business, a figure (BENCHMARKS.md), not an assertion.
  const std::uint64_t counted =
      st.spin_count + st.unpolled_published + st.stale_published + st.free_run_published;
  EXPECT_LE(counted, st.odom_published);
  EXPECT_GE(counted + 1, st.odom_published) << "spin_late " << st.spin_late;
  EXPECT_GE(st.free_run_published, 1u);  // the first write
  EXPECT_GT(st.spin_count, 0u);
  EXPECT_GT(st.spin_wait_sum_ns, 0);
  EXPECT_EQ(st.last_published, final_sample.stamp);
  EXPECT_EQ(st.write_errors, 0u);
}

// LateDueTicks: a SimLoop hook that makes the loop late exactly for the ticks the bridge is due
// to publish: the first tick that wakes at least 9.5 ms (a 100 Hz period less half a loop
// period) after the sample the bridge published last comes kLate later. Records those ticks.
class LateDueTicks {
 public:
  static constexpr TimeNs kLate = 600'000;
  void watch(const Bridge* b) { bridge_ = b; }
  // late: the SimLoop hook (loop thread).
  TimeNs late(std::int64_t k) {
    constexpr TimeNs kMs = 1'000'000;
    const Bridge* b = bridge_.load();
    const TimeNs last = b ? b->stats().last_published : 0;
    if (last == 0 || last == delayed_for_ || test::monotonic_now() < last + 10 * kMs - kMs / 2) {
      return 0;
    }
    delayed_for_ = last;
    std::lock_guard g(m_);
    delayed_.insert(k);
    return kLate;
  }
  bool delayed(std::int64_t k) {
    std::lock_guard g(m_);
    return delayed_.count(k) > 0;
  }

 private:
  std::atomic<const Bridge*> bridge_{nullptr};
  TimeNs delayed_for_ = 0;  // loop thread: the last_published a tick was delayed for
  std::mutex m_;
  std::set<std::int64_t> delayed_;
};

TEST(Ros2Bridge, ALateDueTickIsWaitedForNotReplacedByThePreviousTick) {
  // At 100 Hz from a 1 kHz loop, the bridge wakes 200 us after the due tick (or spin_us before
  // it and polls until spin_us after it); the loop here delivers that tick 600 us late. The
  // bridge must wait for it and publish it, not the tick before it (1 ms older when read, so
  // 1.2+ ms old when received). Received by the Cyclone peer, which prints each sample's tick.
  // 120 samples (1.2 s) per run, not 40: one burst of load that starves the bridge for ~40 ms
  // (four periods; CI's debug-asan stage saw one, 4 stale of 37) then stays under the bound.
  setenv("CYCLONEDDS_URI", test::kCycloneLoopbackXml, 1);
  const std::string emulator = ODO_PEER_EMULATOR;
  const std::string peer = emulator.empty() ? ODO_CYCLONE_PEER : emulator + " " + ODO_CYCLONE_PEER;
  for (const int spin_us : {0, 300}) {
    SCOPED_TRACE("spin_us = " + std::to_string(spin_us));
    Config c = loopback_config(test_domain(4), 100);
    c.spin_us = spin_us;
    LateDueTicks late;
    test::SimLoop loop(1000, [&](std::int64_t k) { return late.late(k); });
    auto b = Bridge::create(
        c, 1000, [&](OdomSample& s) { return loop.read(s); }, nullptr);
    ASSERT_TRUE(b.ok()) << b.error().message;
    late.watch(b->get());
    ASSERT_TRUE((*b)->start().ok());
    loop.start();
    const PeerRun r =
        run_peer(peer + " --domain " + std::to_string(test_domain(4)) + " --odom 120 --timeout 30");
    loop.stop();
    (*b)->stop();
    ASSERT_EQ(r.status, 0) << (r.lines.empty() ? "" : r.lines.back());
    int received = 0, stale = 0;
    std::string stale_ticks;  // for the message
    for (const auto& l : r.lines) {
      const auto t = split(l);
      if (t.size() < 7 || t[0] != "odom") continue;
      // The first messages may predate the phase lock (and the first delayed tick).
      if (++received <= 3) continue;
      // Stale: the tick just before a delayed one, what a bridge that does not wait publishes.
      // The delayed tick or a later one (a bridge that woke late itself) is right.
      const std::int64_t k = std::llround(std::strtod(t[6].c_str(), nullptr) * 1024.0);
      if (late.delayed(k + 1)) {
        ++stale;
        stale_ticks += " " + std::to_string(k);
      }
    }
    ASSERT_GE(received, 120);
    // A thread that woke more than half a period late may fall back to the newest sample once
    // or twice; a bridge that does not wait publishes stale ticks every period.
    EXPECT_LE(stale, (received - 3) / 10) << "of " << received - 3 << ":" << stale_ticks;
    const BridgeStats st = (*b)->stats();
    EXPECT_GT(st.due_waits, 0u);
    EXPECT_EQ(st.write_errors, 0u);
  }
}

}  // namespace
}  // namespace odo::ros2
