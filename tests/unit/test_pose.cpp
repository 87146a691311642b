#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "odo/odometry/pose.hpp"

namespace odo {
namespace {

constexpr double kPi = std::numbers::pi;

TEST(ArcStep, StraightLine) {
  // d_L = d_R = 1 m: no turn, the centre moves 1 m along x.
  const Pose2 p = arc_step({}, 1.0, 1.0, 0.34);
  EXPECT_DOUBLE_EQ(p.x, 1.0);
  EXPECT_DOUBLE_EQ(p.y, 0.0);
  EXPECT_DOUBLE_EQ(p.theta, 0.0);
}

TEST(ArcStep, StraightLineAlongHeading) {
  // Heading 30 deg, 2 m straight: (2 cos 30, 2 sin 30) = (sqrt(3), 1).
  const Pose2 p = arc_step({0, 0, kPi / 6}, 2.0, 2.0, 0.34);
  EXPECT_NEAR(p.x, std::sqrt(3.0), 1e-15);
  EXPECT_NEAR(p.y, 1.0, 1e-15);
}

TEST(ArcStep, OnTheSpotTurn) {
  // d_L = -0.1, d_R = +0.1, b = 0.4: dtheta = (0.1 - (-0.1)) / 0.4 = 0.5 rad, centre fixed.
  const Pose2 p = arc_step({1.0, 2.0, 0.0}, -0.1, 0.1, 0.4);
  EXPECT_DOUBLE_EQ(p.x, 1.0);
  EXPECT_DOUBLE_EQ(p.y, 2.0);
  EXPECT_DOUBLE_EQ(p.theta, 0.5);
}

TEST(ArcStep, QuarterCircleInOneStep) {
  // Circle of radius R = 1 m to the left, b = 0.34: wheel radii R -+ b/2 = 0.83 and 1.17 m.
  // A quarter: d_L = 0.83 * pi/2, d_R = 1.17 * pi/2, dtheta = (1.17-0.83)*(pi/2)/0.34 = pi/2.
  // The centre goes from (0, 0) to (R sin 90, R (1 - cos 90)) = (1, 1).
  const Pose2 p = arc_step({}, 0.83 * kPi / 2, 1.17 * kPi / 2, 0.34);
  EXPECT_NEAR(p.x, 1.0, 1e-14);
  EXPECT_NEAR(p.y, 1.0, 1e-14);
  EXPECT_NEAR(p.theta, kPi / 2, 1e-15);
}

TEST(ArcStep, FullCircleReturnsToStart) {
  // A full circle (dtheta = 2 pi) in one step: chord = ds * sin(pi)/pi = 0, back at the start.
  const Pose2 p = arc_step({}, 0.83 * 2 * kPi, 1.17 * 2 * kPi, 0.34);
  EXPECT_NEAR(p.x, 0.0, 1e-14);
  EXPECT_NEAR(p.y, 0.0, 1e-14);
  EXPECT_NEAR(p.theta, 2 * kPi, 1e-14);
}

TEST(PoseIntegrator, FullCircleInManyStepsReturnsToStart) {
  // Same circle cut into 10 000 equal ticks; heading stays cumulative (2 pi, not 0).
  PoseIntegrator in;
  const int n = 10000;
  for (int i = 0; i < n; ++i) in.step(0.83 * 2 * kPi / n, 1.17 * 2 * kPi / n, 0.34);
  EXPECT_NEAR(in.pose().x, 0.0, 1e-12);
  EXPECT_NEAR(in.pose().y, 0.0, 1e-12);
  EXPECT_NEAR(in.pose().theta, 2 * kPi, 1e-12);
}

TEST(PoseIntegrator, TwoTurnsOnTheSpotKeepCumulativeHeading) {
  // d_R - d_L = 2 * 0.17 * 4 pi over b = 0.34 gives 4 pi: two CCW turns.
  PoseIntegrator in;
  for (int i = 0; i < 400; ++i) in.step(-0.17 * 4 * kPi / 400, 0.17 * 4 * kPi / 400, 0.34);
  EXPECT_NEAR(in.pose().theta, 4 * kPi, 1e-12);
  EXPECT_NEAR(in.pose().x, 0.0, 1e-15);
  EXPECT_NEAR(in.pose().y, 0.0, 1e-15);
}

TEST(PoseIntegrator, MatchesArcStepOnRandomTicks) {
  // The cached sin/cos path must give the same pose as the plain arc formula.
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> d(-0.02, 0.03);
  PoseIntegrator in;
  Pose2 ref;
  for (int i = 0; i < 100000; ++i) {
    const double l = d(rng), r = d(rng);
    in.step(l, r, 0.34);
    ref = arc_step(ref, l, r, 0.34);
  }
  EXPECT_NEAR(in.pose().x, ref.x, 1e-9);
  EXPECT_NEAR(in.pose().y, ref.y, 1e-9);
  EXPECT_NEAR(in.pose().theta, ref.theta, 1e-12);
  EXPECT_NEAR(in.sin_theta(), std::sin(in.pose().theta), 1e-12);
  EXPECT_NEAR(in.cos_theta(), std::cos(in.pose().theta), 1e-12);
}

TEST(ReportStep, Eq26UsesNewHeading) {
  // Eq. 2.3-2.6 on the quarter circle in one step: theta_1 = pi/2, and the whole
  // dU = (0.83 + 1.17)/2 * pi/2 = pi/2 goes along the new heading: (0, pi/2).
  const Pose2 p = report_step({}, 0.83 * kPi / 2, 1.17 * kPi / 2, 0.34);
  EXPECT_NEAR(p.x, 0.0, 1e-15);
  EXPECT_NEAR(p.y, kPi / 2, 1e-15);
  EXPECT_NEAR(p.theta, kPi / 2, 1e-15);
}

TEST(ReportStep, ConvergesToArcWithSmallTicks) {
  // With 100 000 ticks per quarter the chord error of Eq. 2.6 is O(1/n): below 2e-5 m.
  Pose2 p;
  const int n = 100000;
  for (int i = 0; i < n; ++i) p = report_step(p, 0.83 * kPi / 2 / n, 1.17 * kPi / 2 / n, 0.34);
  EXPECT_NEAR(p.x, 1.0, 2e-5);
  EXPECT_NEAR(p.y, 1.0, 2e-5);
}

TEST(WrapAngle, IntoMinusPiPi) {
  EXPECT_DOUBLE_EQ(wrap_angle(kPi), kPi);
  EXPECT_DOUBLE_EQ(wrap_angle(-kPi), kPi);
  EXPECT_NEAR(wrap_angle(3 * kPi), kPi, 1e-15);
  EXPECT_NEAR(wrap_angle(2 * kPi + 0.25), 0.25, 1e-15);
  EXPECT_NEAR(wrap_angle(-kPi / 2), -kPi / 2, 1e-15);
  EXPECT_NEAR(wrap_angle(-7 * kPi / 2), kPi / 2, 1e-14);
}

TEST(Odometry, CountsToPoseAndVelocity) {
  // c_m = pi * 0.15 / (16 * 2048); 1000 counts on both wheels in 0.01 s:
  // d = 1000 c_m = 0.0143810 m, v = d / 0.01 = 1.43810 m/s, w = 0.
  KinematicParams p{0.15, 2048, 16, 0.34, 0.34, 1.0, 1.0};
  Odometry o(*Kinematics::create(p));
  o.update(1000, 1000, 0.01);
  const double d = 1000 * kPi * 0.15 / 32768.0;
  EXPECT_NEAR(o.pose().x, d, 1e-15);
  EXPECT_NEAR(o.linear_velocity(), d / 0.01, 1e-12);
  EXPECT_DOUBLE_EQ(o.angular_velocity(), 0.0);
  // Then -1000 / +1000: on the spot, w = 2 * d / 0.34 / 0.01.
  o.update(-1000, 1000, 0.01);
  EXPECT_NEAR(o.angular_velocity(), 2 * d / 0.34 / 0.01, 1e-9);
  EXPECT_NEAR(o.linear_velocity(), 0.0, 1e-15);
  EXPECT_NEAR(o.distance(), d, 1e-15);
}

// Skid-steer ICR offset (Mandow et al. 2007): with x_icr the body turns about the point x_icr
// ahead of its centre and (R further) to the side, i.e. a constant twist rotates the centre about
// the body-frame point (x_icr, ds/dtheta).
Odometry skid_odometry(double x_icr) {
  KinematicParams p{0.15, 2048, 16, 0.5, 0.5, 1.0, 1.0};
  p.x_icr = x_icr;
  return Odometry(*Kinematics::create(p));
}

TEST(OdometryIcr, SpotTurnMovesCentreAlongChordAboutTheIcr) {
  // b = 0.5, d_R = -d_L = pi b / 4 = pi/8: dtheta = pi/2, ds = 0. The centre rotates by pi/2
  // about the ICR at (0.05, 0): (0, 0) - (0.05, 0) = (-0.05, 0) turned by 90 deg is (0, -0.05),
  // so the centre ends at (0.05, -0.05), a chord of 0.05 sqrt(2) = 70.7 mm. The step's formula:
  // across = -0.05 * (pi/2) * sinc(pi/4) = -0.05 * (pi/2) * (sqrt(2)/2) / (pi/4) = -0.05 sqrt(2)
  // at the mean heading pi/4: (-sin, cos)(pi/4) * across = (0.05, -0.05).
  Odometry o = skid_odometry(0.05);
  o.update_travel(-kPi / 8, kPi / 8, 0.01);
  EXPECT_NEAR(o.pose().x, 0.05, 1e-15);
  EXPECT_NEAR(o.pose().y, -0.05, 1e-15);
  EXPECT_NEAR(o.pose().theta, kPi / 2, 1e-15);
  // The same turn in 1000 ticks (series half-angles, the rotor) lands on the same point: a
  // constant twist's exact steps compose.
  Odometry m = skid_odometry(0.05);
  for (int i = 0; i < 1000; ++i) m.update_travel(-kPi / 8000, kPi / 8000, 0.001);
  EXPECT_NEAR(m.pose().x, 0.05, 1e-13);
  EXPECT_NEAR(m.pose().y, -0.05, 1e-13);
}

TEST(OdometryIcr, GyroHeadingDrivesTheSlide) {
  // A spot turn whose heading change comes from the gyro (pi/2) while the wheels claim more
  // (d = +-0.5 m on b = 0.5: 2 rad): the slide is -x_icr times the fused dtheta, so the centre
  // ends at (0.05, -0.05) as in the wheels' spot turn above. The covariance, shifted to the ICR
  // and back, grows and stays symmetric.
  Odometry o = skid_odometry(0.05);
  o.advance_fused(-0.5, 0.5, 0.01, kPi / 2, 0.0, true, 1e-4);
  EXPECT_NEAR(o.pose().x, 0.05, 1e-15);
  EXPECT_NEAR(o.pose().y, -0.05, 1e-15);
  const Cov3& c = o.covariance();
  EXPECT_GT(c[0], 0.0);
  EXPECT_GT(c[8], 0.0);
  EXPECT_EQ(c[1], c[3]);
  EXPECT_EQ(c[2], c[6]);
  EXPECT_EQ(c[5], c[7]);
}

TEST(OdometryIcr, QuarterArcRotatesAboutTheOffsetCentre) {
  // R = ds/dtheta = 1 m to the left, b = 0.5, dtheta = pi/2: d_L = (1 - 0.25) pi/2,
  // d_R = (1 + 0.25) pi/2. Centre of rotation at body (0.05, 1); the centre's offset from it,
  // (-0.05, -1), turned by 90 deg is (1, -0.05): the centre ends at (1.05, 0.95) (without x_icr
  // it would be (1, 1)). arc_step_icr is the same step on a Pose2.
  Odometry o = skid_odometry(0.05);
  o.update_travel(0.75 * kPi / 2, 1.25 * kPi / 2, 0.01);
  EXPECT_NEAR(o.pose().x, 1.05, 1e-15);
  EXPECT_NEAR(o.pose().y, 0.95, 1e-15);
  const Pose2 a = arc_step_icr({}, 0.75 * kPi / 2, 1.25 * kPi / 2, 0.5, 0.05);
  EXPECT_NEAR(a.x, 1.05, 1e-15);
  EXPECT_NEAR(a.y, 0.95, 1e-15);
  // A straight tick has no turn and so no slide.
  Odometry s = skid_odometry(0.05);
  s.update_travel(0.2, 0.2, 0.01);
  EXPECT_EQ(s.pose().x, 0.2);
  EXPECT_EQ(s.pose().y, 0.0);
}

TEST(OdometryIcr, ZeroOffsetIsBitIdenticalToThePlainStep) {
  // x_icr = 0 takes step_arc: on random ticks the pose and covariance equal those of an Odometry
  // built without the field bit for bit; arc_step_icr with 0 is arc_step (to rounding).
  KinematicParams p{0.15, 2048, 16, 0.5, 0.5, 1.0, 1.0};
  Odometry plain(*Kinematics::create(p));
  Odometry zero = skid_odometry(0.0);
  std::mt19937 rng(7);
  std::uniform_int_distribution<int> counts(-3000, 3000);
  Pose2 a{}, b{};
  for (int i = 0; i < 5000; ++i) {
    const int l = counts(rng), r = counts(rng);
    plain.advance(l, r, 0.001);
    zero.advance(l, r, 0.001);
    a = arc_step(a, l * 1e-5, r * 1e-5, 0.5);
    b = arc_step_icr(b, l * 1e-5, r * 1e-5, 0.5, 0.0);
  }
  EXPECT_EQ(plain.pose().x, zero.pose().x);
  EXPECT_EQ(plain.pose().y, zero.pose().y);
  EXPECT_EQ(plain.pose().theta, zero.pose().theta);
  EXPECT_EQ(plain.covariance(), zero.covariance());
  EXPECT_NEAR(a.x, b.x, 1e-12);
  EXPECT_NEAR(a.y, b.y, 1e-12);
}

}  // namespace
}  // namespace odo
