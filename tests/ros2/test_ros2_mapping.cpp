// Mapping of the planar odometry to ROS 2 message fields, against hand-derived numbers and the
// layout nav_msgs/geometry_msgs document: "Row-major representation of the 6x6 covariance matrix.
// The orientation parameters use a fixed-axis representation. In order, the parameters are:
// (x, y, z, rotation about X axis, rotation about Y axis, rotation about Z axis)".
#include <gtest/gtest.h>

#include <cmath>

#include "odo/ros2/mapping.hpp"

namespace odo::ros2 {
namespace {

// Element (row, col) of a row-major 6x6, as geometry_msgs documents it.
double at(const Cov6& c, int row, int col) {
  return c[row * 6 + col];
}

// expect_unobserved: z (14), roll (21) and pitch (28) carry kUnobservedVariance, and m has
// exactly `nonzero` non-zero entries (nothing placed where it should not be).
void expect_unobserved(const Cov6& m, int nonzero) {
  EXPECT_EQ(m[14], kUnobservedVariance);
  EXPECT_EQ(m[21], kUnobservedVariance);
  EXPECT_EQ(m[28], kUnobservedVariance);
  int n = 0;
  for (double v : m) n += v != 0.0;
  EXPECT_EQ(n, nonzero);
}

TEST(Ros2Mapping, PoseCovarianceLayoutFollowsGeometryMsgs) {
  // Distinct entries so that a transposed or shifted placement shows: our 3x3 over (x, y, theta)
  // = [[11 12 13] [21 22 23] [31 32 33]] (not symmetric on purpose, to see row vs column).
  const Cov3 c = {11, 12, 13, 21, 22, 23, 31, 32, 33};
  const Cov6 m = pose_covariance_6x6(c);
  // x is parameter 0, y parameter 1, rotation about Z parameter 5.
  EXPECT_EQ(at(m, 0, 0), 11);
  EXPECT_EQ(at(m, 0, 1), 12);
  EXPECT_EQ(at(m, 0, 5), 13);
  EXPECT_EQ(at(m, 1, 0), 21);
  EXPECT_EQ(at(m, 1, 5), 23);
  EXPECT_EQ(at(m, 5, 0), 31);
  EXPECT_EQ(at(m, 5, 1), 32);
  EXPECT_EQ(at(m, 5, 5), 33);
  // Flat indices a ROS user reads off the message: [0] xx, [7] yy, [35] yaw-yaw, [5] x-yaw,
  // [30] yaw-x (row 5 * 6 + col 0).
  EXPECT_EQ(m[0], 11);
  EXPECT_EQ(m[7], 22);
  EXPECT_EQ(m[35], 33);
  EXPECT_EQ(m[5], 13);
  EXPECT_EQ(m[30], 31);
  // z, roll and pitch are unobserved: large variance, no correlation.
  expect_unobserved(m, 9 + 3);
}

TEST(Ros2Mapping, TwistCovarianceLayout) {
  const Cov2 c = {1.5, 2.5, 3.5, 4.5};  // (v, omega) rows
  const Cov6 m = twist_covariance_6x6(c);
  EXPECT_EQ(m[0], 1.5);                    // vx vx
  EXPECT_EQ(m[5], 2.5);                    // vx wz
  EXPECT_EQ(m[30], 3.5);                   // wz vx
  EXPECT_EQ(m[35], 4.5);                   // wz wz
  EXPECT_EQ(m[7], kLateralSpeedVariance);  // vy: the non-holonomic constraint, small
  expect_unobserved(m, 4 + 4);
}

TEST(Ros2Mapping, QuaternionFromYaw) {
  // theta = pi/2: q = (0, 0, sin(pi/4), cos(pi/4)) = (0, 0, 0.70710678, 0.70710678).
  Quaternion q = quaternion_from_yaw(M_PI / 2);
  EXPECT_EQ(q.x, 0.0);
  EXPECT_EQ(q.y, 0.0);
  EXPECT_NEAR(q.z, std::sqrt(0.5), 1e-15);
  EXPECT_NEAR(q.w, std::sqrt(0.5), 1e-15);
  // Cumulative theta = 2 pi + pi/2 is the same rotation and gives the same (w >= 0) quaternion;
  // without the wrap it would be -q.
  Quaternion q2 = quaternion_from_yaw(2 * M_PI + M_PI / 2);
  EXPECT_NEAR(q2.z, q.z, 1e-15);
  EXPECT_NEAR(q2.w, q.w, 1e-15);
  // theta = -3 pi / 4 + 2 pi (= 5 pi / 4): wraps to -3 pi / 4, q = (0, 0, -sin(3 pi / 8),
  // cos(3 pi / 8)) = (0, 0, -0.92387953, 0.38268343).
  Quaternion q3 = quaternion_from_yaw(5 * M_PI / 4);
  EXPECT_NEAR(q3.z, -0.9238795325112867, 1e-15);
  EXPECT_NEAR(q3.w, 0.3826834323650898, 1e-15);
  EXPECT_NEAR(q3.z * q3.z + q3.w * q3.w, 1.0, 1e-15);
  // And back: yaw of each.
  EXPECT_NEAR(yaw_from_quaternion(q), M_PI / 2, 1e-15);
  EXPECT_NEAR(yaw_from_quaternion(q3), -3 * M_PI / 4, 1e-15);
  // Scale does not matter.
  EXPECT_NEAR(yaw_from_quaternion({0, 0, 2 * q.z, 2 * q.w}), M_PI / 2, 1e-15);
}

TEST(Ros2Mapping, StampIsMonotonicPlusOffsetWithFloorSeconds) {
  // Monotonic 12.345678901 s + offset 1'700'000'000 s - 0.5 s = 1'700'000'011.845678901 s.
  const TimeNs mono = 12'345'678'901;
  const TimeNs offset = 1'700'000'000 * kNsPerSecond - 500'000'000;
  auto t = to_ros_time(mono, offset);
  ASSERT_TRUE(t.ok());
  EXPECT_EQ(t->sec, 1'700'000'011);
  EXPECT_EQ(t->nanosec, 845'678'901u);
  // -1.7 s is {sec -2, nanosec 3e8} (builtin_interfaces/Time's own example).
  auto neg = to_ros_time(-1'700'000'000, 0);
  ASSERT_TRUE(neg.ok());
  EXPECT_EQ(neg->sec, -2);
  EXPECT_EQ(neg->nanosec, 300'000'000u);
  // Past 2038-01-19 03:14:07 UTC the int32 seconds overflow: an error, not a wrapped stamp.
  auto late = to_ros_time(0, (static_cast<TimeNs>(INT32_MAX) + 1) * kNsPerSecond);
  ASSERT_FALSE(late.ok());
  EXPECT_NE(late.error().message.find("int32"), std::string::npos);
}

TEST(Ros2Mapping, WallClockStepMovesTheNextStampByTheStep) {
  // The same monotonic sample mapped before and after a 3.25 s backward step of CLOCK_REALTIME:
  // the stamp moves by exactly the step (the offset is re-read at every publish).
  const TimeNs mono = 5 * kNsPerSecond;
  const TimeNs before = 1'000 * kNsPerSecond;
  const TimeNs after = before - 3'250'000'000;
  auto a = to_ros_time(mono, before);
  auto b = to_ros_time(mono, after);
  ASSERT_TRUE(a.ok() && b.ok());
  const TimeNs ta = static_cast<TimeNs>(a->sec) * kNsPerSecond + a->nanosec;
  const TimeNs tb = static_cast<TimeNs>(b->sec) * kNsPerSecond + b->nanosec;
  EXPECT_EQ(ta - tb, 3'250'000'000);
}

TEST(Ros2Mapping, OdometryFields) {
  OdomSample s;
  s.stamp = 2 * kNsPerSecond + 5;
  s.x = 1.25;
  s.y = -0.5;
  s.theta = M_PI;  // wraps to pi (in (-pi, pi]): q = (0, 0, 1, cos(pi/2) ~ 6e-17)
  s.pose_cov = {1, 0, 0, 0, 2, 0, 0, 0, 3};
  s.v = 0.4;
  s.omega = -0.2;
  s.twist_cov = {4, 0, 0, 5};
  auto f = odometry_fields(s, 10 * kNsPerSecond);
  ASSERT_TRUE(f.ok());
  EXPECT_EQ(f->stamp.sec, 12);
  EXPECT_EQ(f->stamp.nanosec, 5u);
  EXPECT_EQ(f->x, 1.25);
  EXPECT_EQ(f->y, -0.5);
  EXPECT_EQ(f->z, 0.0);
  EXPECT_NEAR(f->orientation.z, 1.0, 1e-15);
  EXPECT_NEAR(f->orientation.w, 0.0, 1e-15);
  EXPECT_EQ(f->pose_cov[0], 1);
  EXPECT_EQ(f->pose_cov[7], 2);
  EXPECT_EQ(f->pose_cov[35], 3);
  // Twist in base_link: forward along x, turn about z, nothing else.
  EXPECT_EQ(f->vx, 0.4);
  EXPECT_EQ(f->vy, 0.0);
  EXPECT_EQ(f->vz, 0.0);
  EXPECT_EQ(f->wx, 0.0);
  EXPECT_EQ(f->wy, 0.0);
  EXPECT_EQ(f->wz, -0.2);
  EXPECT_EQ(f->twist_cov[0], 4);
  EXPECT_EQ(f->twist_cov[35], 5);
}

TEST(Ros2Mapping, SetPoseFromFields) {
  // yaw 0.7: q = (0, 0, sin 0.35, cos 0.35); covariance diag x 0.01, y 0.02, yaw 0.03 at [0],
  // [7], [35], x-yaw 0.004 at [5] and [30]; z/roll/pitch entries ignored.
  Cov6 c{};
  c[0] = 0.01;
  c[7] = 0.02;
  c[35] = 0.03;
  c[5] = c[30] = 0.004;
  c[14] = 99;
  auto p = set_pose_from_fields({7, 8}, 1.5, -2.5, {0, 0, std::sin(0.35), std::cos(0.35)}, c);
  ASSERT_TRUE(p.ok());
  EXPECT_EQ(p->stamp.sec, 7);
  EXPECT_EQ(p->set_pose.pose.x, 1.5);
  EXPECT_EQ(p->set_pose.pose.y, -2.5);
  EXPECT_NEAR(p->set_pose.pose.theta, 0.7, 1e-15);
  EXPECT_EQ(p->cov[0], 0.01);
  EXPECT_EQ(p->cov[4], 0.02);
  EXPECT_EQ(p->cov[8], 0.03);
  EXPECT_EQ(p->cov[2], 0.004);
  EXPECT_EQ(p->cov[6], 0.004);
  // Rejections name what is wrong.
  auto nan = set_pose_from_fields({}, NAN, 0, {0, 0, 0, 1}, c);
  ASSERT_FALSE(nan.ok());
  EXPECT_NE(nan.error().message.find("position"), std::string::npos);
  auto zero_q = set_pose_from_fields({}, 0, 0, {0, 0, 0, 0}, c);
  ASSERT_FALSE(zero_q.ok());
  EXPECT_NE(zero_q.error().message.find("quaternion"), std::string::npos);
  Cov6 neg = c;
  neg[7] = -1;
  auto bad_cov = set_pose_from_fields({}, 0, 0, {0, 0, 0, 1}, neg);
  ASSERT_FALSE(bad_cov.ok());
  EXPECT_NE(bad_cov.error().message.find("index 7"), std::string::npos);
}

}  // namespace
}  // namespace odo::ros2
