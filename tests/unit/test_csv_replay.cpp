#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <sstream>

#include "odo/analysis/replay.hpp"
#include "odo/odometry/gyrodometry.hpp"

namespace odo::fw {
namespace {

Kinematics kin(double c_l = 1.0, double c_r = 1.0) {
  // c_m = pi * 0.1 / 1000 = 3.14159e-4 m per count (Dn = 0.1 m, Ce = 1000, n = 1).
  KinematicParams p{0.1, 1000, 1, 0.3, 0.3, c_l, c_r};
  return *Kinematics::create(p);
}

TEST(Replay, StraightRun) {
  // 1000 counts on both wheels = one wheel turn = pi * 0.1 m forward.
  std::istringstream in("t,left,right\n0,0,0\n0.5,500,500\n1.0,1000,1000\n");
  auto r = analysis::replay_ticks(in, "run.csv", kin(), 64);
  ASSERT_TRUE(r.ok()) << r.error().message;
  EXPECT_NEAR(r->pose.x, std::numbers::pi * 0.1, 1e-14);
  EXPECT_NEAR(r->pose.y, 0.0, 1e-15);
  EXPECT_NEAR(r->distance, std::numbers::pi * 0.1, 1e-14);
  EXPECT_EQ(r->samples, 3u);
}

TEST(Replay, SixteenBitWrapSignedAndUnsignedAgree) {
  // 65500 -> 100 (unsigned) is +136 counts; signed form: -36 -> 100 is also +136.
  std::istringstream u("t,left,right\n0,65500,65500\n1,100,100\n");
  std::istringstream s("t,left,right\n0,-36,-36\n1,100,100\n");
  auto ru = analysis::replay_ticks(u, "u.csv", kin(), 16);
  auto rs = analysis::replay_ticks(s, "s.csv", kin(), 16);
  ASSERT_TRUE(ru.ok() && rs.ok());
  EXPECT_NEAR(ru->pose.x, 136 * std::numbers::pi * 0.1 / 1000, 1e-15);
  EXPECT_DOUBLE_EQ(ru->pose.x, rs->pose.x);
}

TEST(Replay, OnTheSpotTurnIsCumulative) {
  // Each wheel 3000 counts in opposite senses: d = 3000 * pi * 1e-4 = 0.942478 m,
  // dtheta = 2 d / b = 2 * 0.942478 / 0.3 = 2 pi: one full turn, theta stays 2 pi.
  std::istringstream in("t,left,right\n0,0,0\n1,-3000,3000\n");
  auto r = analysis::replay_ticks(in, "turn.csv", kin(), 32);
  ASSERT_TRUE(r.ok());
  EXPECT_NEAR(r->pose.theta, 2 * std::numbers::pi, 1e-12);
  EXPECT_NEAR(r->distance, 0.0, 1e-15);
}

struct Bad {
  const char* text;
  const char* expect;
};
class ReplayRejects : public ::testing::TestWithParam<Bad> {};

TEST_P(ReplayRejects, NamesLineAndField) {
  std::istringstream in(GetParam().text);
  auto r = analysis::replay_ticks(in, "f.csv", kin(), 16);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().message.find(GetParam().expect), std::string::npos) << r.error().message;
}

INSTANTIATE_TEST_SUITE_P(
    Cases, ReplayRejects,
    ::testing::Values(Bad{"", "f.csv:1: empty file"},
                      Bad{"t,left\n0,1\n", "missing column 'right'"},
                      Bad{"t,left,right,speed\n", "unknown column 'speed'"},
                      Bad{"t,left,right\n0,0,0\n1,x,0\n", "f.csv:3: field 'left' = 'x'"},
                      Bad{"t,left,right\n0,0,0\n1,1.5,0\n", "f.csv:3: field 'left' = '1.5'"},
                      Bad{"t,left,right\nnan,0,0\n", "f.csv:2: field 't' = 'nan' is not a finite"},
                      Bad{"t,left,right\n0,0\n", "f.csv:2: expected 3 fields, found 2"},
                      Bad{"t,left,right\n0,0,70000\n", "f.csv:2: field 'right': reading 70000"},
                      Bad{"t,left,right\n1,0,0\n0.5,1,1\n",
                          "f.csv:3: field 't' = 0.5 s goes backwards"}));

// A log with a gyro column: 200 Hz, 1 s still (the fusion learns the bias 0.01 rad/s), then
// straight at 1000 counts/s on both wheels; between 2.0 and 2.1 s the left wheel reads 20 extra
// counts a tick (a bump odometry sees as a turn, 20 * 3.14159e-4 / 0.3 = 0.0209 rad a tick) that
// the gyro does not see (it reads its bias only).
std::string bump_log(bool with_gyro) {
  std::ostringstream o;
  o.precision(17);
  o << "t,left,right" << (with_gyro ? ",gyro_z" : "") << "\n";
  std::int64_t l = 0, r = 0;
  for (int i = 0; i <= 600; ++i) {
    const double t = i * 0.005;
    if (i > 200) {
      l += 5 + (i > 400 && i <= 420 ? 20 : 0);
      r += 5;
    }
    o << t << "," << l << "," << r;
    if (with_gyro) o << "," << 0.01;
    o << "\n";
  }
  return o.str();
}

TEST(Replay, GyroColumnIsFusedExactlyAsTheLoopRule) {
  // The independent integration: the same rows stepped through Gyrodometry and
  // Odometry::update_fused by hand (no CSV): the replay must agree bit for bit.
  const Kinematics k = kin();
  GyrodometryParams p;
  p.tick = 0.005;
  p.heading_quantum = (k.metres_per_count_left() + k.metres_per_count_right()) / k.wheelbase();
  Gyrodometry fusion = Gyrodometry::create(p).value();
  Odometry odom(k);
  std::int64_t l = 0, r = 0;
  for (int i = 1; i <= 600; ++i) {
    const std::int64_t dl = i > 200 ? 5 + (i > 400 && i <= 420 ? 20 : 0) : 0;
    const std::int64_t dr = i > 200 ? 5 : 0;
    l += dl;
    r += dr;
    FusionInput in;
    in.dt = i * 0.005 - (i - 1) * 0.005;
    in.d_left = static_cast<double>(dl) * k.metres_per_count_left();
    in.d_right = static_cast<double>(dr) * k.metres_per_count_right();
    in.wheelbase = k.wheelbase();
    in.gyro.rate_z = 0.01;
    in.gyro.samples = 1;
    const FusedTick f = fusion.step(in);
    odom.update_fused(dl, dr, in.dt, f.dtheta, f.ds);
  }
  std::istringstream log(bump_log(true));
  auto fused = analysis::replay_ticks(log, "gyro.csv", k, 64, analysis::ReplayGyro{});
  ASSERT_TRUE(fused.ok()) << fused.error().message;
  EXPECT_TRUE(fused->fused);
  EXPECT_EQ(fused->pose.x, odom.pose().x);
  EXPECT_EQ(fused->pose.y, odom.pose().y);
  EXPECT_EQ(fused->pose.theta, odom.pose().theta);
  EXPECT_EQ(fused->fusion.disagreements, fusion.counters().disagreements);
  EXPECT_EQ(fused->fusion.accel_events, fusion.counters().accel_events);
  EXPECT_EQ(fused->fusion.gyro_used_ticks, fusion.counters().gyro_used_ticks);
  EXPECT_GE(fused->fusion.gyro_used_ticks, 20u);  // the whole bump came from the gyro
  // Odometry alone turns by the bump: 20 ticks * 20 counts * 3.14159e-4 m / 0.3 m = 0.41888 rad
  // clockwise; the fusion removes it to within the window's quantisation and the bias residual.
  std::istringstream plain_log(bump_log(true));
  analysis::ReplayGyro off;
  off.use = false;
  auto plain = analysis::replay_ticks(plain_log, "gyro.csv", k, 64, off);
  ASSERT_TRUE(plain.ok());
  EXPECT_FALSE(plain->fused);
  EXPECT_NEAR(plain->pose.theta, -400 * std::numbers::pi * 0.1 / 1000 / 0.3, 1e-12);
  EXPECT_LT(std::fabs(fused->pose.theta), std::fabs(plain->pose.theta) / 100.0);
  // Without the column the replay is the plain one.
  std::istringstream no_col(bump_log(false));
  auto none = analysis::replay_ticks(no_col, "nogyro.csv", k, 64, analysis::ReplayGyro{});
  ASSERT_TRUE(none.ok());
  EXPECT_EQ(none->pose.theta, plain->pose.theta);
}

TEST(Replay, BadGyroFieldsNameFileLineAndField) {
  std::istringstream nan_row("t,left,right,gyro_z\n0,0,0,0\n0.005,1,1,nan\n");
  auto r = analysis::replay_ticks(nan_row, "g.csv", kin(), 64, analysis::ReplayGyro{});
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().message.find("g.csv:3"), std::string::npos) << r.error().message;
  EXPECT_NE(r.error().message.find("gyro_z"), std::string::npos) << r.error().message;
  std::istringstream missing("t,left,right,gyro_z\n0,0,0,0\n0.005,1,1\n");
  r = analysis::replay_ticks(missing, "g.csv", kin(), 64, analysis::ReplayGyro{});
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().message.find("g.csv:3"), std::string::npos) << r.error().message;
}

}  // namespace
}  // namespace odo::fw
