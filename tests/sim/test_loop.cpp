#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <vector>

#include "sim_fixture.hpp"

namespace odo::test {
namespace {

sim::Scenario wiggle() {
  // Arbitrary wheel-velocity profile: forward, arc, reverse arc, spin.
  // About 1.5e5 counts forward in all, so 16-bit counters wrap twice over.
  return {{3.0, 4.0, 4.0}, {2.0, 2.0, 5.0}, {2.5, -3.0, -1.0}, {1.5, -4.0, 4.0}, {5.0, 5.0, 5.0}};
}

TEST(Loop, SixteenBitCountersWrapWithoutLoss) {
  // Start the 16-bit counters 50 counts below the wrap; the profile drives ~10^5 counts, so
  // they wrap many times. The pose must equal that of 64-bit counters exactly.
  const auto k = *Kinematics::create(nominal_labmate());
  sim::RobotGeometry g;
  SimRun narrow(g, k, wiggle(), 16, 32767 - 50);
  SimRun wide(g, k, wiggle(), 64);
  narrow.drive();
  wide.drive();
  EXPECT_EQ(narrow.loop->odometry().pose().x, wide.loop->odometry().pose().x);
  EXPECT_EQ(narrow.loop->odometry().pose().y, wide.loop->odometry().pose().y);
  EXPECT_EQ(narrow.loop->odometry().pose().theta, wide.loop->odometry().pose().theta);
  EXPECT_GT(std::fabs(wide.robot.counts_left()), 65536);
}

// Records what each tick integrated: the sample time and the count deltas (wheel travel divided
// by metres per count, which is an integer count up to rounding).
struct TickRecorder final : loop::TickObserver {
  explicit TickRecorder(const loop::OdometryLoop*& l) : loop(l) { stamps.reserve(4096); }
  void on_tick(const loop::LoopSnapshot& s) noexcept override {
    const Odometry& o = loop->odometry();
    stamps.push_back(s.stamp);
    counts_left += std::llround(o.last_d_left() / o.kinematics().metres_per_count_left());
    counts_right += std::llround(o.last_d_right() / o.kinematics().metres_per_count_right());
  }
  const loop::OdometryLoop*& loop;
  std::vector<TimeNs> stamps;
  std::int64_t counts_left = 0;
  std::int64_t counts_right = 0;
};

TEST(Loop, OverrunsSkipPeriodsAndLoseNoCount) {
  // Every read takes 25 ms of a 10 ms period: each tick misses two deadlines, the loop skips
  // them, and the cumulative counts still integrate to the same pose as an on-time loop. The
  // slow loop also has 16-bit counters starting near the wrap, so overruns and wraps mix
  // (~1.5e5 counts forward, 0.03 s * 4 m/s / 1.44e-5 m = 8300 counts per tick < 2^15).
  const auto k = *Kinematics::create(nominal_labmate());
  sim::RobotGeometry g;
  SimRun slow(g, k, wiggle(), 16, 32767 - 50);
  SimRun fast(g, k, wiggle());
  slow.encoder.set_read_delay(&slow.clock, 25'000'000);
  const loop::OdometryLoop* slow_loop = slow.loop;
  TickRecorder rec(slow_loop);
  slow.loop->add_observer(&rec);
  slow.drive();
  fast.drive();
  const auto& st = slow.loop->stats();
  EXPECT_GT(st.missed_deadlines, 0u);
  EXPECT_EQ(fast.loop->stats().missed_deadlines, 0u);
  // Ticks happen every 30 ms: 25 ms read, then the next free 10 ms boundary; no bursts.
  EXPECT_EQ(st.missed_deadlines, 2 * st.ticks);
  ASSERT_EQ(rec.stamps.size(), st.ticks);
  for (std::size_t i = 1; i < rec.stamps.size(); ++i)
    ASSERT_EQ(rec.stamps[i] - rec.stamps[i - 1], 30'000'000) << "tick " << i;

  // No count is lost: the deltas the loop integrated sum exactly to the robot's counts.
  EXPECT_EQ(rec.counts_left, slow.robot.counts_left());
  EXPECT_EQ(rec.counts_right, slow.robot.counts_right());
  EXPECT_GT(std::abs(slow.robot.counts_left()), 65536);  // the 16-bit counters wrapped

  // The pose stays exact: it is bit for bit the pose of integrating the true counts over the
  // long (30 ms) intervals, computed here independently of the loop from a second robot
  // sampled at the same instants with 64-bit counts.
  auto ref_robot = *sim::SimRobot::create(g, wiggle());
  Odometry ref(k);
  std::int64_t pl = 0, pr = 0;
  TimeNs pt = 0;  // the reference reading of start() is at time 0 with zero counts
  for (const TimeNs t : rec.stamps) {
    ref_robot.advance_to(t);
    ref.update(ref_robot.counts_left() - pl, ref_robot.counts_right() - pr, to_seconds(t - pt));
    pl = ref_robot.counts_left();
    pr = ref_robot.counts_right();
    pt = t;
  }
  const Pose2& a = slow.loop->odometry().pose();
  EXPECT_EQ(a.x, ref.pose().x);
  EXPECT_EQ(a.y, ref.pose().y);
  EXPECT_EQ(a.theta, ref.pose().theta);
  EXPECT_EQ(slow.loop->odometry().linear_velocity(), ref.linear_velocity());
  EXPECT_EQ(slow.loop->odometry().distance(), ref.distance());

  // Against the on-time loop: the heading is a sum of count deltas, independent of how the
  // ticks cut the drive, so both agree to rounding, and both agree with the truth to one count.
  const Pose2& b = fast.loop->odometry().pose();
  EXPECT_NEAR(a.theta, b.theta, 1e-12);
  EXPECT_NEAR(a.theta, slow.robot.true_pose().theta, k.metres_per_count() / g.wheelbase);
  // Position depends on the partition only where a tick straddles a change of wheel speeds
  // (the arc of such a tick is not the true two-piece path): 5 straddled changes, each at most
  // v * dt * dtheta ~ 0.15 m/s * 0.03 s * 0.03 rad ~ 0.1 mm.
  EXPECT_NEAR(a.x, slow.robot.true_pose().x, 5e-4);
  EXPECT_NEAR(a.y, slow.robot.true_pose().y, 5e-4);
  EXPECT_NEAR(b.x, fast.robot.true_pose().x, 5e-4);
  EXPECT_NEAR(b.y, fast.robot.true_pose().y, 5e-4);
}

TEST(Loop, SetPoseTakesEffectAtNextTick) {
  const auto k = *Kinematics::create(nominal_labmate());
  sim::RobotGeometry g;
  SimRun run(g, k, {{1.0, 0.0, 0.0}});
  run.loop->start();
  run.loop->tick();
  run.loop->post(loop::SetPose{{1.5, -2.0, 0.25}});
  EXPECT_DOUBLE_EQ(run.loop->odometry().pose().x, 0.0);  // not before the next tick
  run.loop->tick();
  EXPECT_DOUBLE_EQ(run.loop->odometry().pose().x, 1.5);
  EXPECT_DOUBLE_EQ(run.loop->odometry().pose().y, -2.0);
  EXPECT_DOUBLE_EQ(run.loop->odometry().pose().theta, 0.25);
}

TEST(Loop, RejectsRateOutsideRange) {
  const auto k = *Kinematics::create(nominal_labmate());
  sim::RobotGeometry g;
  auto robot = *sim::SimRobot::create(g, {});
  sim::SimEncoderSource enc(robot);
  sim::VirtualClock clock;
  auto l = loop::OdometryLoop::create(loop::LoopConfig{10.0}, k, enc, clock);
  ASSERT_FALSE(l.ok());
  EXPECT_NE(l.error().message.find("[50, 2000] Hz"), std::string::npos);
}

TEST(Loop, PublishesSnapshotsWithStats) {
  const auto k = *Kinematics::create(nominal_labmate());
  sim::RobotGeometry g;
  SimRun run(g, k, {{1.0, 2.0, 2.0}});
  run.drive(0.0);
  loop::LoopSnapshot s;
  ASSERT_TRUE(run.loop->snapshots().latest(s));
  EXPECT_EQ(s.tick, run.loop->stats().ticks);
  EXPECT_EQ(s.tick, 100u);  // 1 s at 100 Hz
  EXPECT_DOUBLE_EQ(s.pose.x, run.loop->odometry().pose().x);
}

TEST(Loop, SnapshotCarriesTimingHistogramSummaries) {
  // On the virtual clock a tick wakes exactly on time (latency 0) and a 2 ms read is the whole
  // compute time. 300 ticks at 100 Hz (at 12, 22, ..., 3002 ms: loop time starts after the 2 ms
  // start-up read). While ticking, the snapshot's summaries are refreshed every kSummaryTicks
  // (last at tick 256); the end of run() publishes the summaries of all 300.
  const auto k = *Kinematics::create(nominal_labmate());
  sim::RobotGeometry g;
  SimRun ticked(g, k, {{2.0, 1.0, 1.0}});
  ticked.encoder.set_read_delay(&ticked.clock, 2'000'000);
  ticked.loop->start();
  for (int i = 0; i < 300; ++i) ticked.loop->tick();
  loop::LoopSnapshot s;
  ASSERT_TRUE(ticked.loop->snapshots().latest(s));
  EXPECT_EQ(s.tick, 300u);
  EXPECT_EQ(s.stats.wakeup_latency.count, 256u);
  EXPECT_EQ(s.stats.wakeup_latency.max, 0);
  EXPECT_EQ(s.stats.wakeup_latency.p99, 0);
  EXPECT_EQ(s.stats.compute_time.count, 256u);
  EXPECT_EQ(s.stats.compute_time.min, 2'000'000);
  EXPECT_EQ(s.stats.compute_time.mean, 2'000'000);
  EXPECT_EQ(s.stats.compute_time.p99, 2'000'000);  // bucket bound clamped to the maximum
  EXPECT_EQ(s.stats.compute_time.p999, 2'000'000);
  EXPECT_EQ(s.stats.compute_time.max, 2'000'000);
  EXPECT_EQ(s.stats.compute_max, 2'000'000);
  EXPECT_EQ(s.stats.missed_deadlines, 0u);
  EXPECT_EQ(ticked.loop->snapshot().stats.compute_time.count, 256u);

  SimRun run(g, k, {{2.0, 1.0, 1.0}});
  run.encoder.set_read_delay(&run.clock, 2'000'000);
  run.drive();
  ASSERT_TRUE(run.loop->snapshots().latest(s));
  EXPECT_EQ(s.tick, 300u);
  EXPECT_EQ(run.loop->stats().compute_time.count, 300u);
  EXPECT_EQ(s.stats.wakeup_latency.count, 300u);
  EXPECT_EQ(s.stats.compute_time.count, 300u);
  EXPECT_EQ(s.stats.compute_time.mean, 2'000'000);
  EXPECT_EQ(run.loop->snapshot().stats.compute_time.count, 300u);
}

}  // namespace
}  // namespace odo::test
