// UMBmark equations (calibration/umbmark.hpp) against hand-derived numbers and the seeds' own
// figures. Every expected value is derived in the comment next to it.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "odo/calibration/umbmark.hpp"

namespace odo::calib {
namespace {

constexpr double kPi = std::numbers::pi;

UmbmarkRun cw(double x, double y) {
  return {Direction::kCw, x, y, std::nullopt, false};
}
UmbmarkRun ccw(double x, double y) {
  return {Direction::kCcw, x, y, std::nullopt, false};
}

// Synthetic runs of a robot with Type A error alpha and Type B error beta on a square of side L,
// from the report's Eq. 6.19/6.20 and their y counterparts (6.10b, 6.6b, 6.14b, 6.18b):
//   x_cw = -2L(a + b), y_cw = -2L(a + b), x_ccw = -2L(a - b), y_ccw = +2L(a - b).
std::vector<UmbmarkRun> model_runs(double a, double b, double L) {
  return {cw(-2 * L * (a + b), -2 * L * (a + b)), ccw(-2 * L * (a - b), 2 * L * (a - b))};
}

TEST(Umbmark, CentresOfGravityOfChongKleemanTable1GiveEmax135mm) {
  // Table 1, before: ccw c.g. (97, -94) mm, cw c.g. (32, 31) mm, E_max,syst = 135 mm.
  // Two runs a direction averaging to the table's c.g.: (95, -90) and (99, -98) -> (97, -94).
  const std::vector<UmbmarkRun> runs{ccw(0.095, -0.090), ccw(0.099, -0.098), cw(0.030, 0.033),
                                     cw(0.034, 0.029)};
  const CentreOfGravity g_cw = centre_of_gravity(runs, Direction::kCw);
  const CentreOfGravity g_ccw = centre_of_gravity(runs, Direction::kCcw);
  EXPECT_EQ(g_cw.n, 2);
  EXPECT_NEAR(g_ccw.x, 0.097, 1e-12);
  EXPECT_NEAR(g_ccw.y, -0.094, 1e-12);
  EXPECT_NEAR(g_cw.x, 0.032, 1e-12);
  EXPECT_NEAR(g_cw.y, 0.031, 1e-12);
  // r_ccw = sqrt(97^2 + 94^2) = sqrt(18245) = 135.07 mm; r_cw = sqrt(32^2 + 31^2) = 44.55 mm.
  EXPECT_NEAR(g_ccw.r, 0.13507, 1e-5);
  EXPECT_NEAR(g_cw.r, 0.04455, 1e-5);
  EXPECT_NEAR(e_max_syst(g_cw, g_ccw), 0.13507, 1e-5);
  EXPECT_EQ(std::lround(e_max_syst(g_cw, g_ccw) * 1e3), 135);
}

TEST(Umbmark, ChongKleemanTable1AfterCalibrationGives30mm) {
  // After: ccw (-26, 16) mm -> 30.53 mm; cw (1.5, 11) mm -> 11.10 mm; table: 30 mm.
  const std::vector<UmbmarkRun> runs{ccw(-0.026, 0.016), cw(0.0015, 0.011)};
  const double e =
      e_max_syst(centre_of_gravity(runs, Direction::kCw), centre_of_gravity(runs, Direction::kCcw));
  EXPECT_NEAR(e, 0.030529, 1e-6);
}

TEST(Umbmark, BumpRunsAreNotPartOfTheCentreOfGravity) {
  std::vector<UmbmarkRun> runs{cw(0.010, 0.020)};
  runs.push_back({Direction::kCw, 5.0, 5.0, 0.1, true});
  const CentreOfGravity g = centre_of_gravity(runs, Direction::kCw);
  EXPECT_EQ(g.n, 1);
  EXPECT_DOUBLE_EQ(g.x, 0.010);
  EXPECT_DOUBLE_EQ(g.y, 0.020);
}

TEST(Umbmark, TypeAandBRecoverTheModelAngles) {
  // alpha = 0.01, beta = 0.002, L = 4: x_cw = y_cw = -8 * 0.012 = -0.096, x_ccw = -8 * 0.008 =
  // -0.064, y_ccw = +0.064. Eq. 6.26a: (-0.096 - 0.064) / -16 = 0.01; 6.26b: (-0.096 - 0.064)
  // / -16 = 0.01; 6.22a: (-0.096 + 0.064) / -16 = 0.002; 6.22b: (-0.096 + 0.064) / -16 = 0.002.
  const auto runs = model_runs(0.01, 0.002, 4.0);
  const TypeAB t = type_ab(centre_of_gravity(runs, Direction::kCw),
                           centre_of_gravity(runs, Direction::kCcw), 4.0);
  EXPECT_NEAR(t.alpha_x, 0.01, 1e-15);
  EXPECT_NEAR(t.alpha_y, 0.01, 1e-15);
  EXPECT_NEAR(t.beta_x, 0.002, 1e-15);
  EXPECT_NEAR(t.beta_y, 0.002, 1e-15);
  EXPECT_NEAR(t.alpha, 0.01, 1e-15);
  EXPECT_NEAR(t.beta, 0.002, 1e-15);
}

TEST(Umbmark, XandYEstimatesAreAveraged) {
  // As above but y_cw = -0.080: alpha_y = (-0.080 - 0.064) / -16 = 0.009, beta_y = (-0.080 +
  // 0.064) / -16 = 0.001; averages alpha = (0.01 + 0.009) / 2 = 0.0095, beta = 0.0015.
  const std::vector<UmbmarkRun> runs{cw(-0.096, -0.080), ccw(-0.064, 0.064)};
  const TypeAB t = type_ab(centre_of_gravity(runs, Direction::kCw),
                           centre_of_gravity(runs, Direction::kCcw), 4.0);
  EXPECT_NEAR(t.alpha_y, 0.009, 1e-15);
  EXPECT_NEAR(t.beta_y, 0.001, 1e-15);
  EXPECT_NEAR(t.alpha, 0.0095, 1e-15);
  EXPECT_NEAR(t.beta, 0.0015, 1e-15);
}

TEST(Umbmark, RadiusAndDiameterRatio) {
  // Eq. 6.23: R = (4/2) / sin(0.001) = 2 / (0.001 - 1.667e-10) = 2000.000333 m.
  const auto r = curvature_radius(0.002, 4.0);
  ASSERT_TRUE(r.has_value());
  EXPECT_NEAR(*r, 2000.000333, 1e-6);
  // Eq. 6.24 with b = 0.34: (R + 0.17)/(R - 0.17) = 1 + 0.34/(R - 0.17) = 1.000170014.
  EXPECT_NEAR(diameter_ratio(r, 0.34), 1.000170014, 1e-9);
  // A leg curving right (beta < 0) gives R < 0 and E_d < 1: the right wheel is the smaller.
  EXPECT_LT(diameter_ratio(curvature_radius(-0.002, 4.0), 0.34), 1.0);
  // Straight legs: no radius, E_d = 1.
  EXPECT_FALSE(curvature_radius(0.0, 4.0).has_value());
  EXPECT_EQ(diameter_ratio(std::nullopt, 0.34), 1.0);
}

TEST(Umbmark, WheelbaseFactorEq629AgainstChongKleemanEq9) {
  // alpha = 1 deg: Eq. 6.29 E_b = 90/(90 - 1) = 1.011236; C&K Eq. 9: 180/179 = 1.005587.
  EXPECT_NEAR(wheelbase_factor(kPi / 180), 90.0 / 89.0, 1e-12);
  EXPECT_NEAR(wheelbase_factor(kPi / 180, WheelbaseFormula::kChongKleeman9), 180.0 / 179.0, 1e-12);
  // The robot turned too far (alpha < 0): its true wheelbase is smaller than believed.
  EXPECT_LT(wheelbase_factor(-0.01), 1.0);
  EXPECT_EQ(wheelbase_factor(0.0), 1.0);
}

TEST(Umbmark, WheelFactorsKeepTheMeanDiameter) {
  // E_d = 1.002: c_L = 2/2.002 = 0.999000999, c_R = 2/(1/1.002 + 1) = 2.004/2.002 = 1.000999001;
  // c_R/c_L = E_d and (c_L + c_R)/2 = 1 (Eq. 6.30).
  const PassFactors f = wheel_factors(1.002);
  EXPECT_NEAR(f.c_l, 0.999000999, 1e-9);
  EXPECT_NEAR(f.c_r, 1.000999001, 1e-9);
  EXPECT_NEAR(f.c_r / f.c_l, 1.002, 1e-12);
  EXPECT_NEAR(0.5 * (f.c_l + f.c_r), 1.0, 1e-12);
}

TEST(Umbmark, PassesComposeByMultiplication) {
  // The robot ran with c_L 1.001, c_R 0.999, b 0.337 m; the pass found c_L 0.9995, c_R 1.0005,
  // E_b 1.01: c_L = 1.001 * 0.9995 = 1.0004995, c_R = 0.999 * 1.0005 = 0.9994995,
  // b = 0.337 * 1.01 = 0.34037 m.
  const Factors f = compose({1.001, 0.999, 0.337}, {0.9995, 1.0005, 1.01});
  EXPECT_NEAR(f.c_l, 1.0004995, 1e-12);
  EXPECT_NEAR(f.c_r, 0.9994995, 1e-12);
  EXPECT_NEAR(f.wheelbase, 0.34037, 1e-12);
  // A pass that finds nothing leaves the factors as they were (not reset to 1).
  const Factors same = compose({1.001, 0.999, 0.337}, {1.0, 1.0, 1.0});
  EXPECT_EQ(same.c_l, 1.001);
  EXPECT_EQ(same.wheelbase, 0.337);
}

TEST(Umbmark, SpreadAndThreeSemRule) {
  // cw (0, 0), (2, 0) mm -> c.g. (1, 0); ccw (0, 10), (0, 14) mm -> c.g. (0, 12).
  // Squared distances 1 + 1 + 4 + 4 = 10 mm^2 over 4 - 2 = 2 degrees of freedom: sigma =
  // sqrt(5) mm = 2.2360680 mm.
  const std::vector<UmbmarkRun> runs{cw(0, 0), cw(0.002, 0), ccw(0, 0.010), ccw(0, 0.014)};
  const auto s = return_spread(runs, centre_of_gravity(runs, Direction::kCw),
                               centre_of_gravity(runs, Direction::kCcw));
  ASSERT_TRUE(s.has_value());
  EXPECT_NEAR(*s, 2.2360680e-3, 1e-9);
  // Two runs in all: no spread can be estimated.
  const std::vector<UmbmarkRun> two{cw(0, 0), ccw(0, 0)};
  EXPECT_FALSE(return_spread(two, centre_of_gravity(two, Direction::kCw),
                             centre_of_gravity(two, Direction::kCcw))
                   .has_value());
  // The report's Experiment 7: sigma = 25 mm, n = 5: SEM = 25/sqrt(5) = 11.18 mm, 3 SEM =
  // 33.5 mm; E_max,syst = 66 mm after the first pass asks for a second, 21 mm does not.
  const double sem = 0.025 / std::sqrt(5.0);
  EXPECT_TRUE(second_pass_recommended(0.066, sem));
  EXPECT_FALSE(second_pass_recommended(0.021, sem));
}

TEST(Umbmark, SetSpreadJudgesTheSetItIsComputedOn) {
  // The runs above: c.g. cw (1, 0) mm, ccw (0, 12) mm -> E_max,syst 12 mm; sigma sqrt(5) mm,
  // n = 2 a direction: SEM = sqrt(5)/sqrt(2) = 1.5811388 mm, 3 SEM = 4.74 mm < 12 mm.
  const std::vector<UmbmarkRun> runs{cw(0, 0), cw(0.002, 0), ccw(0, 0.010), ccw(0, 0.014)};
  const auto g_cw = centre_of_gravity(runs, Direction::kCw);
  const auto g_ccw = centre_of_gravity(runs, Direction::kCcw);
  const SetSpread s = set_spread(runs, g_cw, g_ccw);
  ASSERT_TRUE(s.sigma.has_value());
  EXPECT_NEAR(*s.sigma, 2.2360680e-3, 1e-9);
  EXPECT_NEAR(s.sem, 1.5811388e-3, 1e-9);
  EXPECT_TRUE(s.worthwhile);
  // A set whose c.g. sit within the noise: cw (0, 0), (2, 0) mm -> (1, 0); ccw (0, -1), (0, 1)
  // mm -> (0, 0): E_max,syst 1 mm; squared distances 1 + 1 + 1 + 1 = 4 mm^2 over 2: sigma =
  // sqrt(2) mm, SEM = sqrt(2)/sqrt(2) = 1 mm, 3 SEM = 3 mm > 1 mm: no pass on these runs.
  const std::vector<UmbmarkRun> quiet{cw(0, 0), cw(0.002, 0), ccw(0, -0.001), ccw(0, 0.001)};
  const SetSpread q = set_spread(quiet, centre_of_gravity(quiet, Direction::kCw),
                                 centre_of_gravity(quiet, Direction::kCcw));
  EXPECT_NEAR(*q.sigma, 1.4142136e-3, 1e-9);
  EXPECT_NEAR(q.sem, 1e-3, 1e-12);
  EXPECT_FALSE(q.worthwhile);
  // umbmark_compute reports the spread of its own input runs.
  UmbmarkInput in;
  in.runs = quiet;
  in.side = 4.0;
  in.current = {1.0, 1.0, 0.34};
  auto r = umbmark_compute(in);
  ASSERT_TRUE(r.ok()) << r.error().message;
  EXPECT_NEAR(r->spread.sem, 1e-3, 1e-12);
  EXPECT_FALSE(r->spread.worthwhile);
}

TEST(Umbmark, ExtendedUmbmarkRemovesTheSystematicBias) {
  // cw plain etheta 0.01, 0.02 -> mu_cw = 0.015 (Eq. 3.6); cw bump runs 0.025, 0.005 ->
  // |0.010|, |-0.010| -> mean 0.010. ccw plain -0.004, -0.006 -> mu_ccw = -0.005; ccw bump runs
  // -0.002, -0.009 -> |0.003|, |-0.004| -> mean 0.0035. Eq. 3.5: 0.010 + 0.0035 = 0.0135 rad.
  std::vector<UmbmarkRun> runs{
      {Direction::kCw, 0, 0, 0.01, false},    {Direction::kCw, 0, 0, 0.02, false},
      {Direction::kCw, 0, 0, 0.025, true},    {Direction::kCw, 0, 0, 0.005, true},
      {Direction::kCcw, 0, 0, -0.004, false}, {Direction::kCcw, 0, 0, -0.006, false},
      {Direction::kCcw, 0, 0, -0.002, true},  {Direction::kCcw, 0, 0, -0.009, true}};
  auto e = eps_theta_nonsys(runs);
  ASSERT_TRUE(e.ok());
  ASSERT_TRUE(e->has_value());
  EXPECT_NEAR(**e, 0.0135, 1e-15);
  // Without bump runs there is no figure; a bump run without the plain runs' etheta is an error.
  EXPECT_FALSE(eps_theta_nonsys(model_runs(0.01, 0.0, 4.0))->has_value());
  std::vector<UmbmarkRun> no_bias{cw(0, 0), {Direction::kCw, 0, 0, 0.02, true}};
  auto bad = eps_theta_nonsys(no_bias);
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.error().message.find("etheta"), std::string::npos);
  EXPECT_NE(bad.error().message.find("cw"), std::string::npos);
}

TEST(Umbmark, ComputeEndToEnd) {
  // alpha = 0.01, beta = 0.002, L = 4, b = 0.34, factors 1: E_d = 1.000170014 (above),
  // c_L = 2/2.000170014 = 0.999915000, c_R = 1.000085000; E_b = (pi/2)/(pi/2 - 0.01) =
  // 1.5707963/1.5607963 = 1.006406986, b_new = 0.34 * E_b = 0.342178375 m.
  UmbmarkInput in;
  in.runs = model_runs(0.01, 0.002, 4.0);
  in.side = 4.0;
  in.current = {1.0, 1.0, 0.34};
  auto r = umbmark_compute(in);
  ASSERT_TRUE(r.ok()) << r.error().message;
  EXPECT_NEAR(r->e_d, 1.000170014, 1e-9);
  EXPECT_NEAR(r->composed.c_l, 0.999915000, 1e-9);
  EXPECT_NEAR(r->composed.c_r, 1.000085000, 1e-9);
  EXPECT_NEAR(r->e_b, 1.006406986, 1e-9);
  EXPECT_NEAR(r->composed.wheelbase, 0.342178375, 1e-9);
  // One run a direction: warned about, and no spread (second pass on the safe side).
  EXPECT_EQ(r->warnings.size(), 2U);
  EXPECT_FALSE(r->spread.sigma.has_value());
  EXPECT_TRUE(r->spread.worthwhile);
  // With factors already in use the result composes: c_L = 1.002 * 0.999915 = 1.001914830.
  in.current = {1.002, 0.998, 0.34};
  auto r2 = umbmark_compute(in);
  ASSERT_TRUE(r2.ok());
  EXPECT_NEAR(r2->composed.c_l, 1.002 * 0.999915000, 1e-9);
  EXPECT_NEAR(r2->composed.c_r, 0.998 * 1.000085000, 1e-9);
}

// factor_sigmas, derived by hand. Three runs a direction on a square of L = 4 m, b = 0.34 m,
// current factors 1: (d, 0), (-d, 0), (0, 0) each, d = 10 mm. Both centres of gravity are
// (0, 0), so alpha = beta = 0: b_new = b, c_l = c_r = 1 (R undefined: E_d = 1).
// Spread: sum |e - cg|^2 = 4 d^2 over n_cw + n_ccw - 2 = 4 dof, sigma = d; each direction's
// SEM s = d / sqrt(3). With k = -4L = -16 and alpha = (alpha_x + alpha_y) / 2, beta likewise:
//   cw.x += s:  alpha_x = s/k, beta_x = s/k    -> alpha = s/2k, beta = s/2k
//   cw.y += s:  alpha_y = s/k, beta_y = s/k    -> alpha = s/2k, beta = s/2k
//   ccw.x += s: alpha_x = s/k, beta_x = -s/k   -> alpha = s/2k, beta = -s/2k
//   ccw.y += s: alpha_y = -s/k, beta_y = s/k   -> alpha = -s/2k, beta = s/2k
// With a = s/32 (= |s/2k|): alpha = -a three times and +a once.
// b_new = b q/(q - alpha) (Eq. 6.29, q = pi/2): its change is b alpha/(q - alpha), so
//   sigma_b^2 = 3 (b a/(q + a))^2 + (b a/(q - a))^2.
// c_l = 2/(E_d + 1) with E_d = (R + b/2)/(R - b/2) and R = (L/2)/sin(beta/2) is exactly
// 1 - b sin(beta/2)/L, c_r = 1 + b sin(beta/2)/L; |beta| = a in all four moves:
//   sigma_cl = sigma_cr = sqrt(4 (b sin(a/2)/L)^2) = 2 b sin(a/2)/L.
// The moves are finite, so these are exact, not first-order: only rounding separates them.
TEST(Umbmark, FactorSigmasFromTheSemOfEachCentreOfGravity) {
  const double d = 0.010, L = 4.0, b = 0.34;
  UmbmarkInput in;
  in.side = L;
  in.current = {1.0, 1.0, b};
  in.runs = {cw(d, 0), cw(-d, 0), cw(0, 0), ccw(d, 0), ccw(-d, 0), ccw(0, 0)};
  auto r = umbmark_compute(in);
  ASSERT_TRUE(r.ok()) << r.error().message;
  ASSERT_TRUE(r->spread.sigma.has_value());
  EXPECT_NEAR(*r->spread.sigma, d, 1e-15);
  const auto sd = factor_sigmas(in, *r);
  ASSERT_TRUE(sd.has_value());
  const double s = d / std::sqrt(3.0), a = s / 32.0, q = kPi / 2.0;
  const double sigma_b = b * std::sqrt(3.0 * std::pow(a / (q + a), 2) + std::pow(a / (q - a), 2));
  const double sigma_c = 2.0 * b * std::sin(a / 2.0) / L;
  EXPECT_NEAR(sd->wheelbase, sigma_b, 1e-12 * sigma_b);
  EXPECT_NEAR(sd->c_l, sigma_c, 1e-9 * sigma_c);
  EXPECT_NEAR(sd->c_r, sigma_c, 1e-9 * sigma_c);
  // Bump runs are not in a centre of gravity: adding one (with its heading) changes nothing.
  in.runs.push_back({Direction::kCw, 0.5, 0.5, 0.01, true});
  in.runs.front().etheta = 0.0;
  auto rb = umbmark_compute(in);
  ASSERT_TRUE(rb.ok()) << rb.error().message;
  const auto sdb = factor_sigmas(in, *rb);
  ASSERT_TRUE(sdb.has_value());
  EXPECT_NEAR(sdb->wheelbase, sigma_b, 1e-12 * sigma_b);
  // Fewer than 3 runs in all: no spread, no sigmas.
  in.runs = {cw(d, 0), ccw(d, 0)};
  auto r2 = umbmark_compute(in);
  ASSERT_TRUE(r2.ok());
  EXPECT_FALSE(factor_sigmas(in, *r2).has_value());
}

TEST(Umbmark, ComputeRejectsBadInputNamingTheField) {
  auto message = [](UmbmarkInput in) {
    auto r = umbmark_compute(in);
    EXPECT_FALSE(r.ok());
    return r.ok() ? std::string() : r.error().message;
  };
  UmbmarkInput ok;
  ok.runs = model_runs(0.01, 0.002, 4.0);
  ok.current = {1.0, 1.0, 0.34};
  UmbmarkInput in = ok;
  in.side = 0.0;
  EXPECT_NE(message(in).find("side"), std::string::npos);
  in = ok;
  in.current.wheelbase = -0.34;
  EXPECT_NE(message(in).find("wheelbase"), std::string::npos);
  in = ok;
  in.current.c_l = 1.5;
  EXPECT_NE(message(in).find("c_l"), std::string::npos);
  in = ok;
  in.runs.pop_back();  // no ccw run
  EXPECT_NE(message(in).find("ccw"), std::string::npos);
  in = ok;
  in.runs[0].ex = std::nan("");
  EXPECT_NE(message(in).find("finite"), std::string::npos);
  in = ok;
  // Millimetres typed as metres: x_cw = -96 "m" gives alpha = 10 rad.
  in.runs = model_runs(10.0, 2.0, 4.0);
  EXPECT_NE(message(in).find("alpha"), std::string::npos);
  in.runs = model_runs(0.0, 0.5, 4.0);
  EXPECT_NE(message(in).find("beta"), std::string::npos);
}

}  // namespace
}  // namespace odo::calib
