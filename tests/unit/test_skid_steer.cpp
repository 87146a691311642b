// The skid-steer body's friction model (issue 38): hand-derived twists of the quasi-static force
// balance, the exact constant-twist step, the loads and the parameter checks.
#include "odo/sim/skid_steer.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

namespace odo::sim {
namespace {

constexpr double kA = 0.131;          // half wheelbase of jackal_skid_params [m]
constexpr double kC = 0.37559 / 2.0;  // half track [m]

TEST(SkidSteer, StraightDriveHasNoSlipAndTheRimSpeed) {
  // vL = vR = v: the twist (v, 0, 0) gives every contact point the rim's velocity (slip 0), so
  // every friction force is 0 and the balance holds; D is strictly convex there, so it is the
  // only twist that does. Warm-started far away to exercise the line search.
  const SkidSteerParams p = jackal_skid_params();
  const SkidSolution s = solve_skid_twist(p, 0.5, 0.5, BodyTwist{-1.0, 0.3, 2.0});
  ASSERT_TRUE(s.converged);
  EXPECT_NEAR(s.twist.vx, 0.5, 1e-12);
  EXPECT_NEAR(s.twist.vy, 0.0, 1e-12);
  EXPECT_NEAR(s.twist.omega, 0.0, 1e-12);
}

TEST(SkidSteer, SymmetricSpotTurnTurnsAboutTheCentre) {
  // vL = -v, vR = v, centre of mass at the centre: by symmetry vx = vy = 0. Front-right wheel at
  // (a, -c): slip (omega c - v, omega a); the four wheels' |slip| are equal, so the r of the law
  // cancels and the moment balance a mu_t^2 (omega a) + c mu_l^2 (omega c - v) = 0 gives
  // omega = v c mu_l^2 / (mu_l^2 c^2 + mu_t^2 a^2). mu_l = mu_t, v = 0.2:
  // omega = 0.2 * 0.187795 / (0.187795^2 + 0.131^2) = 0.71639252 rad/s, an effective track
  // 2v / omega = 0.5583531 m = 1.48660 t.
  const SkidSteerParams p = jackal_skid_params();
  const SkidSolution s = solve_skid_twist(p, -0.2, 0.2);
  ASSERT_TRUE(s.converged);
  EXPECT_NEAR(s.twist.vx, 0.0, 1e-12);
  EXPECT_NEAR(s.twist.vy, 0.0, 1e-12);
  EXPECT_NEAR(s.twist.omega, 0.2 * kC / (kC * kC + kA * kA), 1e-12);
  EXPECT_NEAR(s.twist.omega, 0.71639252, 1e-8);
  EXPECT_NEAR(skid_effective_track(p, -0.2, 0.2), 0.5583531, 1e-7);
}

TEST(SkidSteer, LateralFrictionRatioSetsTheSpotTurnTrack) {
  // Same balance with mu_t / mu_l = 0.5: omega = v c / (c^2 + 0.25 a^2), track
  // 2 (c^2 + 0.25 a^2) / c = 0.37559 + 0.5 * 0.131^2 / 0.187795 = 0.4212808 m.
  SkidSteerParams p = jackal_skid_params();
  p.mu_long = 0.8;
  p.mu_lat = 0.4;
  EXPECT_NEAR(skid_effective_track(p, -0.3, 0.3), 0.4212808, 1e-7);
}

TEST(SkidSteer, NoLateralFrictionGivesTheGeometricTrack) {
  // mu_lat = 0: no lateral forces; left slips sL = vx - omega c - vL, right sR = vx + omega c - vR
  // with forces -g(s), g odd and increasing, equal loads. Force: 2 g(sL) + 2 g(sR) = 0 gives
  // sL = -sR; moment: c (2 g(sR) - 2 g(sL)) = 0 gives sL = sR; so sL = sR = 0: the wheels roll
  // without slip, omega = (vR - vL) / t = 0.2 / 0.37559 and vx = (vL + vR) / 2 = 0.2.
  SkidSteerParams p = jackal_skid_params();
  p.mu_lat = 0.0;
  const SkidSolution s = solve_skid_twist(p, 0.1, 0.3);
  ASSERT_TRUE(s.converged);
  EXPECT_NEAR(s.twist.omega, 0.2 / 0.37559, 1e-12);
  EXPECT_NEAR(s.twist.vx, 0.2, 1e-12);
  EXPECT_NEAR(s.twist.vy, 0.0, 1e-12);  // free; the warm start (0) is kept
}

TEST(SkidSteer, SolvedTwistBalancesForceAndMoment) {
  // An arc and an off-centre mass: no closed form, but the wrench at the solution vanishes while
  // at rest with the rims turning the floor pushes the body forward with about mu m g.
  SkidSteerParams p = jackal_skid_params();
  p.com_x = 0.04;
  const SkidSolution s = solve_skid_twist(p, 0.15, 0.25);
  ASSERT_TRUE(s.converged);
  const Wrench w = skid_wrench(p, s.twist, 0.15, 0.25);
  EXPECT_NEAR(w.fx, 0.0, 1e-9);
  EXPECT_NEAR(w.fy, 0.0, 1e-9);
  EXPECT_NEAR(w.mz, 0.0, 1e-9);
  // Body at rest, rims at 0.2 m/s: slip (-0.2, 0) on each wheel, force N mu_l^2 0.2 / sqrt((mu_l
  // 0.2)^2 + eps^2) = N mu_l / sqrt(1 + (eps / 0.16)^2): the total 0.8 * 17 * 9.81 * 0.99998.
  const Wrench rest = skid_wrench(jackal_skid_params(), BodyTwist{}, 0.2, 0.2);
  EXPECT_NEAR(rest.fx, 0.8 * 17.0 * 9.81 / std::sqrt(1.0 + std::pow(1e-3 / 0.16, 2)), 1e-9);
  EXPECT_NEAR(rest.fy, 0.0, 1e-12);
  EXPECT_NEAR(rest.mz, 0.0, 1e-12);
}

TEST(SkidSteer, OffCentreMassShiftsTheTurningCentre) {
  // With the mass ahead of the centre the front wheels grip more, so the body turns about a
  // point nearer the front axle: the geometric centre slides sideways (Mandow et al.'s
  // longitudinal ICR offset), outward of the turn: vy = -x_icr omega < 0 for a CCW turn.
  SkidSteerParams p = jackal_skid_params();
  p.com_x = 0.05;
  const SkidSolution s = solve_skid_twist(p, -0.2, 0.2);
  ASSERT_TRUE(s.converged);
  EXPECT_NEAR(s.twist.vx, 0.0, 1e-12);
  EXPECT_LT(s.twist.vy, -1e-3);
}

TEST(SkidSteer, WheelLoadsFollowTheCentreOfMass) {
  // com_x = 0.05: front wheel m g (a + 0.05) / (4a) = 17 * 9.81 * 0.181 / 0.524 = 57.605668 N,
  // rear 17 * 9.81 * 0.081 / 0.524 = 25.779332 N; together m g / 2 per side.
  SkidSteerParams p = jackal_skid_params();
  p.com_x = 0.05;
  EXPECT_NEAR(wheel_load(p, true), 57.605668, 1e-6);
  EXPECT_NEAR(wheel_load(p, false), 25.779332, 1e-6);
  EXPECT_NEAR(2.0 * (wheel_load(p, true) + wheel_load(p, false)), 17.0 * 9.81, 1e-9);
}

TEST(SkidSteer, TwistStepIsExact) {
  // vx = 1 m/s, omega = pi/2 rad/s for 1 s: a quarter circle of radius 2/pi from heading 0 ends
  // at (2/pi, 2/pi, pi/2). A pure sideways twist from heading pi/2 moves along -x.
  const double pi = std::numbers::pi;
  const Pose2 q = twist_step(Pose2{}, BodyTwist{1.0, 0.0, pi / 2.0}, 1.0);
  EXPECT_NEAR(q.x, 2.0 / pi, 1e-15);
  EXPECT_NEAR(q.y, 2.0 / pi, 1e-15);
  EXPECT_NEAR(q.theta, pi / 2.0, 1e-15);
  const Pose2 r = twist_step(Pose2{1.0, 2.0, pi / 2.0}, BodyTwist{0.0, 0.5, 0.0}, 2.0);
  EXPECT_NEAR(r.x, 0.0, 1e-15);
  EXPECT_NEAR(r.y, 2.0, 1e-15);
  // The series branch (|omega dt| < 1e-4) against the closed form with 1 - cos = 2 sin^2(th/2)
  // (no cancellation): x = (vx sin th - vy 2 sin^2(th/2)) / omega, y = (vx 2 sin^2(th/2) +
  // vy sin th) / omega.
  for (const double w : {0.99e-4, 1.01e-4}) {
    const Pose2 a = twist_step(Pose2{}, BodyTwist{0.3, 0.1, w}, 1.0);
    const double s2 = 2.0 * std::pow(std::sin(w / 2.0), 2);
    EXPECT_NEAR(a.x, (0.3 * std::sin(w) - 0.1 * s2) / w, 1e-15);
    EXPECT_NEAR(a.y, (0.3 * s2 + 0.1 * std::sin(w)) / w, 1e-15);
  }
}

TEST(SkidSteer, BodyMetersTheSpotTurns) {
  // 1000 steps of 1 ms spinning (rims -0.2, +0.2 m/s) then 1000 straight: the metered ratio is
  // the spot-turn track 0.5583531 m and the straight steps do not count.
  auto body = SkidSteerBody::create(jackal_skid_params());
  ASSERT_TRUE(body.ok());
  Pose2 pose;
  for (int i = 0; i < 1000; ++i) pose = body->step(pose, -2e-4, 2e-4, 1e-3);
  const double turned = pose.theta;
  for (int i = 0; i < 1000; ++i) pose = body->step(pose, 2e-4, 2e-4, 1e-3);
  EXPECT_NEAR(turned, 0.71639252, 1e-7);
  EXPECT_NEAR(pose.theta, turned, 1e-12);
  EXPECT_NEAR(body->spot_turn_rim() / body->spot_turn_angle(), 0.5583531, 1e-7);
  EXPECT_EQ(body->unconverged(), 0U);
}

TEST(SkidSteer, ParametersOutOfRangeNameTheField) {
  SkidSteerParams p = jackal_skid_params();
  p.com_x = 0.2;  // beyond the front axle
  auto s = check_skid_params(p);
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.error().message.find("com_x"), std::string::npos) << s.error().message;
  p = jackal_skid_params();
  p.mu_long = 0.0;
  auto m = SkidSteerBody::create(p);
  ASSERT_FALSE(m.ok());
  EXPECT_NE(m.error().message.find("mu_long"), std::string::npos) << m.error().message;
  EXPECT_TRUE(check_skid_params(jackal_skid_params()).ok());
}

}  // namespace
}  // namespace odo::sim
