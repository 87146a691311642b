// Self-calibration of the ICR offset x_ICR (issue 38, Mandow et al. 2007): the excursion model
// with x_ICR and its Jacobian column against hand-derived numbers. c_m = 1e-4 m/count, b = 0.5 m,
// so a spin of n counts per wheel (-n left, +n right) turns by 2 n 1e-4 / 0.5 = 4e-4 n rad.
//
// The model (calibration/src/selfcal_model.cpp, add_icr): the point P = C + x u(theta),
// u = (cos, sin), moves like a plain base's centre, so an excursion from heading theta0 to theta1
// ends at the plain arcs' end plus x (u(theta0) - u(theta1)). Its Jacobian column for x is
// (cos theta0 - cos theta1, sin theta0 - sin theta1, 0): (1, -1, 0) for a left quarter turn
// from heading 0, (2, 0, 0) for a half turn, (0, 0, 0) for a full turn.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <optional>
#include <vector>

#include "odo/calibration/selfcal.hpp"

namespace odo::calib {
namespace {

constexpr double kCm = 1e-4;  // [m/count]
constexpr double kPi = std::numbers::pi;

// spin: counts of a spin in place by `angle` [rad] at b = 0.5 m (n = angle / 4e-4 per wheel).
std::vector<LegCounts> spin(double angle) {
  const double n = angle / 4e-4;
  return {{-n, n}};
}

// icr_config: c_L, c_R, b known (prior sigma 1e-9), x_ICR fitted with prior sigma 0.1 m around 0.
SelfCalConfig icr_config() {
  SelfCalConfig c;
  c.metres_per_count = kCm;
  c.in_use = {1.0, 1.0, 0.5};
  c.odometry_noise = {0.0, 0.0};
  c.hold_out_every = 0;
  c.prior_sigma_factor = 1e-9;
  c.prior_sigma_wheelbase = 1e-9;
  c.icr = IcrFit::kFit;
  c.prior_sigma_x_icr = 0.1;
  return c;
}

// one_excursion: fixes (sigma s in x, y and theta) at the origin and at `end`.
FixTrack one_excursion(const std::vector<LegCounts>& legs, const Pose2& end, double s) {
  FixTrack t;
  t.fixes = {PoseFix{0, 0.0, 0.0, 0.0, s, s},
             PoseFix{kNsPerSecond, end.x, end.y, wrap_angle(end.theta), s, s}};
  t.legs = {legs};
  return t;
}

TEST(SelfCalIcr, AQuarterTurnSlidesTheCentreByXTimesTheHeadingChord) {
  // x = 0.05 m, spin by pi/2 from heading 0: end = 0.05 (u(0) - u(pi/2)) = (0.05, -0.05), 70.7 mm
  // (README's 90 degree spot turn); a full square of four such turns with 1 m straights between
  // ends where it started: the four slides are one vector turned by 90 degrees four times.
  const Pose2 q = predict_excursion({}, spin(kPi / 2), {1.0, 1.0, 0.5}, kCm, 0.05);
  EXPECT_NEAR(q.x, 0.05, 1e-12);
  EXPECT_NEAR(q.y, -0.05, 1e-12);
  EXPECT_NEAR(q.theta, kPi / 2, 1e-12);
  std::vector<LegCounts> square;
  for (int i = 0; i < 4; ++i) {
    square.push_back({10000, 10000});
    square.push_back(spin(kPi / 2)[0]);
  }
  const Pose2 sq = predict_excursion({}, square, {1.0, 1.0, 0.5}, kCm, 0.05);
  EXPECT_NEAR(sq.x, 0.0, 1e-12);
  EXPECT_NEAR(sq.y, 0.0, 1e-12);
}

TEST(SelfCalIcr, JacobianColumnGivesTheHandDerivedSigma) {
  // Truth x = 0, so the estimate is 0 and the start-fix propagation G = d end / d start is the
  // identity (end = start); S = 2 s^2 I (both fixes). c_L, c_R, b are held by their 1e-9 priors
  // and do not couple to x (their columns have no x, y part at x = 0, and x's no theta part).
  // Information of x: J_x^T S^-1 J_x + 1 / sigma_p^2 with J_x = (cos 0 - cos a, sin 0 - sin a):
  //   quarter turn (1, -1): 2 / (2 s^2) = 1 / s^2  -> sigma = (1e6 + 100)^-1/2 = 9.99950e-4 m
  //   half turn    (2,  0): 4 / (2 s^2) = 2 / s^2  -> sigma = (2e6 + 100)^-1/2 = 7.07089e-4 m
  //   full turn    (0,  0): nothing                -> sigma = sigma_p = 0.1 m
  // with s = 1e-3 m (and rad), sigma_p = 0.1 m.
  const double s = 1e-3;
  struct Case {
    double angle, sigma;
  };
  for (const Case k : {Case{kPi / 2, 1.0 / std::sqrt(1e6 + 100)},
                       Case{kPi, 1.0 / std::sqrt(2e6 + 100)}, Case{2 * kPi, 0.1}}) {
    SCOPED_TRACE(k.angle);
    auto r = fit_fixes(one_excursion(spin(k.angle), {0.0, 0.0, k.angle}, s), icr_config());
    ASSERT_TRUE(r) << r.error().message;
    EXPECT_NEAR(r->x_icr, 0.0, 1e-12);
    EXPECT_NEAR(r->sigma_x_icr / k.sigma, 1.0, 1e-6);
    EXPECT_NEAR(std::sqrt(cov_at(r->covariance, 3, 3)), r->sigma_x_icr, 1e-15);
    // The bound (2 mm by default): the turns show x, the full turn (a closed square's net turn)
    // does not, so its x_ICR is not applied.
    EXPECT_EQ(r->x_icr_observable, k.angle < 1.5 * kPi);
  }
}

TEST(SelfCalIcr, FitRecoversTheOffsetFromAQuarterTurn) {
  // The fixes of a quarter turn with x = 0.03 m: (0.03, -0.03, pi/2). The data are exact and
  // the prior (0.1 m around 0) weighs 1e-8 of them (s = 1 um): x = 0.03 within 1e-9.
  const Pose2 end = predict_excursion({}, spin(kPi / 2), {1.0, 1.0, 0.5}, kCm, 0.03);
  auto r = fit_fixes(one_excursion(spin(kPi / 2), end, 1e-6), icr_config());
  ASSERT_TRUE(r) << r.error().message;
  EXPECT_NEAR(r->x_icr, 0.03, 1e-9);
  EXPECT_TRUE(r->x_icr_observable);
}

TEST(SelfCalIcr, AllFourFromMixedExcursions) {
  // Straights, spins and arcs of a robot with c_L 0.995, c_R 1.004, b 0.41 m, x 0.02 m from exact
  // fixes: all four within 1e-8 (default priors). The same fixes fitted with x held at 0 (the
  // plain arcs) do not fit: the slide is not a track.
  const Factors truth{0.995, 1.004, 0.41};
  std::vector<std::vector<LegCounts>> legs = {{{10000, 10000}, {-2000, 2000}},
                                              {{3000, 6000}},
                                              {{2500, -2500}, {8000, 8000}},
                                              {{6000, 2000}, {-1000, 1000}},
                                              {{4000, 4000}, {1500, -1500}}};
  FixTrack t;
  t.fixes.push_back(PoseFix{0, 0.0, 0.0, 0.0, 1e-6, 1e-6});
  Pose2 q;
  for (std::size_t i = 0; i < legs.size(); ++i) {
    q = predict_excursion(q, legs[i], truth, kCm, 0.02);
    t.fixes.push_back(PoseFix{static_cast<TimeNs>(i + 1) * kNsPerSecond, q.x, q.y,
                              wrap_angle(q.theta), 1e-6, 1e-6});
  }
  t.legs = legs;
  SelfCalConfig c = icr_config();
  c.prior_sigma_factor = 0.01;
  c.prior_sigma_wheelbase = 0.02;
  auto r = fit_fixes(t, c);
  ASSERT_TRUE(r) << r.error().message;
  EXPECT_NEAR(r->estimate.c_l, 0.995, 1e-8);
  EXPECT_NEAR(r->estimate.c_r, 1.004, 1e-8);
  EXPECT_NEAR(r->estimate.wheelbase, 0.41, 1e-8);
  EXPECT_NEAR(r->x_icr, 0.02, 1e-8);
  EXPECT_LT(r->chi2_per_dof, 1e-6);
  c.icr = IcrFit::kFixed;
  auto plain = fit_fixes(t, c);
  ASSERT_TRUE(plain) << plain.error().message;
  EXPECT_EQ(plain->sigma_x_icr, 0.0);
  EXPECT_FALSE(plain->x_icr_observable);
  // The plain arcs cannot explain the slides: the outlier rejection throws fixes away (4 of the
  // 6 here, seen) and b comes out off.
  EXPECT_GE(plain->fixes_rejected, 3);
  EXPECT_GT(std::fabs(plain->estimate.wheelbase - 0.41), 1e-4);
  // Held at the true offset, the 3-parameter fit is exact again (the model uses x in use).
  c.x_icr = 0.02;
  auto held = fit_fixes(t, c);
  ASSERT_TRUE(held) << held.error().message;
  EXPECT_NEAR(held->estimate.wheelbase, 0.41, 1e-8);
  EXPECT_EQ(held->x_icr, 0.02);
  EXPECT_LT(held->chi2_per_dof, 1e-6);
}

TEST(SelfCalIcr, XIcrOutOfTheKinematicsRangeIsNamed) {
  SelfCalConfig c = icr_config();
  c.x_icr = 3.0;
  auto r = check_selfcal_config(c);
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().message.find("x_icr"), std::string::npos) << r.error().message;
  c.x_icr = 0.0;
  c.max_sigma_x_icr = 0.0;
  auto m = check_selfcal_config(c);
  ASSERT_FALSE(m);
  EXPECT_NE(m.error().message.find("max_sigma_x_icr"), std::string::npos) << m.error().message;
}

}  // namespace
}  // namespace odo::calib
