#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <sstream>

#include "odo/analysis/replay.hpp"

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

}  // namespace
}  // namespace odo::fw
