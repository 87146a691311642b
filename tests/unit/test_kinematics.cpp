#include <gtest/gtest.h>

#include <cmath>

#include "odo/odometry/kinematics.hpp"

namespace odo {
namespace {

KinematicParams valid() {
  KinematicParams p;
  p.wheel_diameter = 0.15;
  p.counts_per_rev = 2048;
  p.gear_ratio = 16;
  p.wheelbase_nominal = 0.34;
  p.wheelbase = 0.34;
  return p;
}

TEST(Kinematics, MetresPerCountIsPiDnOverNCe) {
  // c_m = pi * Dn / (n * Ce) = pi * 0.15 / (16 * 2048) = 0.471238898038469 / 32768
  //     = 1.438107...e-5 m per count.
  auto k = Kinematics::create(valid());
  ASSERT_TRUE(k.ok());
  EXPECT_NEAR(k->metres_per_count(), 0.471238898038469 / 32768.0, 1e-18);
  EXPECT_DOUBLE_EQ(k->metres_per_count_left(), k->metres_per_count());
}

TEST(Kinematics, FactorsScaleEachWheel) {
  // c_L = 1.002, c_R = 0.998: the per-wheel distances are c_X * c_m (UMBmark Eq. 6.35).
  KinematicParams p = valid();
  p.c_l = 1.002;
  p.c_r = 0.998;
  auto k = Kinematics::create(p);
  ASSERT_TRUE(k.ok());
  EXPECT_DOUBLE_EQ(k->metres_per_count_left(), 1.002 * k->metres_per_count());
  EXPECT_DOUBLE_EQ(k->metres_per_count_right(), 0.998 * k->metres_per_count());
}

struct BadCase {
  const char* field;
  void (*mutate)(KinematicParams&);
};

class KinematicsRejects : public ::testing::TestWithParam<BadCase> {};

TEST_P(KinematicsRejects, EachInvalidFieldWithItsName) {
  KinematicParams p = valid();
  GetParam().mutate(p);
  auto k = Kinematics::create(p);
  ASSERT_FALSE(k.ok());
  EXPECT_EQ(k.error().code, Errc::kInvalidArgument);
  EXPECT_NE(k.error().message.find(GetParam().field), std::string::npos) << k.error().message;
  EXPECT_NE(k.error().message.find("allowed range"), std::string::npos) << k.error().message;
}

INSTANTIATE_TEST_SUITE_P(
    Fields, KinematicsRejects,
    ::testing::Values(
        BadCase{"wheel_diameter", [](KinematicParams& p) { p.wheel_diameter = 0.0; }},
        BadCase{"wheel_diameter", [](KinematicParams& p) { p.wheel_diameter = 150.0; }},
        BadCase{"wheel_diameter", [](KinematicParams& p) { p.wheel_diameter = NAN; }},
        BadCase{"counts_per_rev", [](KinematicParams& p) { p.counts_per_rev = 0.0; }},
        BadCase{"gear_ratio", [](KinematicParams& p) { p.gear_ratio = -2.0; }},
        BadCase{"wheelbase_nominal", [](KinematicParams& p) { p.wheelbase_nominal = INFINITY; }},
        BadCase{"wheelbase", [](KinematicParams& p) { p.wheelbase = 340.0; }},
        BadCase{"c_l", [](KinematicParams& p) { p.c_l = 0.0; }},
        BadCase{"c_r", [](KinematicParams& p) { p.c_r = 2.0; }},
        BadCase{"x_icr", [](KinematicParams& p) { p.x_icr = 50.0; }},  // mm written for m
        BadCase{"x_icr", [](KinematicParams& p) { p.x_icr = NAN; }}));

}  // namespace
}  // namespace odo
