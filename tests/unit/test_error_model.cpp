// Chong-Kleeman error model: hand-derived values, consistency, brute-force agreement, stability.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include "loglog_slope.hpp"
#include "odo/odometry/error_model.hpp"
#include "odo/odometry/pose.hpp"

namespace odo {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kL = 0.00040, kR = 0.00058;  // the paper's fitted values [m^(1/2)]
constexpr double kB = 0.34;                   // LabMate wheelbase [m]
const ErrorModelParams kParams{kL, kR};

enum { XX = 0, XY = 1, XT = 2, YY = 4, YT = 5, TT = 8 };

// expect_cov_near: every entry within rel * sqrt(P_ii P_jj) (for the diagonal: rel * P_ii), i.e.
// relative to the scale of the entry's correlation, so exactly-zero entries are handled.
void expect_cov_near(const Cov3& a, const Cov3& b, double rel, const char* what) {
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      const double scale = std::sqrt(std::fabs(b[4 * i]) * std::fabs(b[4 * j]));
      EXPECT_LE(std::fabs(a[3 * i + j] - b[3 * i + j]), rel * scale + 1e-300)
          << what << ": entry (" << i << "," << j << ") " << a[3 * i + j] << " vs " << b[3 * i + j];
    }
  }
}

TEST(ErrorModel, StraightLineHandValues) {
  // d_L = d_R = D = 10 m, b = 0.34 m. w_L = k_L^2 D = 1.6e-7 * 10 = 1.6e-6 m^2,
  // w_R = k_R^2 D = 3.364e-7 * 10 = 3.364e-6 m^2, W+ = 4.964e-6, W- = -1.764e-6.
  // Straight-line limit (derivation in error_model.cpp):
  //   xx = W+/4 = 1.241e-6                     yy = W+ D^2/(3 b^2) = 4.964e-4/0.3468
  //   xy = -W- D/(4b) = 1.764e-5/1.36          xt = -W-/(2b) = 1.764e-6/0.68
  //   yt = W+ D/(2 b^2) = 4.964e-5/0.2312      tt = W+/b^2 = 4.964e-6/0.1156
  Cov3 p{};
  propagate_arc(p, 0.0, 10.0, 10.0, kB, kParams);
  EXPECT_NEAR(p[XX], 1.241e-6, 1e-20);
  EXPECT_NEAR(p[YY], 4.964e-4 / 0.3468, 1e-17);
  EXPECT_NEAR(p[XY], 1.764e-5 / 1.36, 1e-18);
  EXPECT_NEAR(p[XT], 1.764e-6 / 0.68, 1e-19);
  EXPECT_NEAR(p[YT], 4.964e-5 / 0.2312, 1e-17);
  EXPECT_NEAR(p[TT], 4.964e-6 / 0.1156, 1e-18);
  EXPECT_EQ(p[1], p[3]);
  EXPECT_EQ(p[2], p[6]);
  EXPECT_EQ(p[5], p[7]);
}

TEST(ErrorModel, SlipVarianceAddsToTheWheelsNoise) {
  // The same straight 10 m with a slip's extra variance on the left wheel only, var_L = 1e-4 m^2
  // (a spread of 1 cm): w_L = 1.6e-6 + 1e-4 = 1.016e-4, w_R = 3.364e-6, W+ = 1.04964e-4,
  // W- = 9.8236e-5, and the straight-line limit as above:
  //   xx = W+/4 = 2.6241e-5         yy = W+ D^2/(3 b^2) = 1.04964e-2/0.3468
  //   xy = -W- D/(4b) = -9.8236e-4/1.36         xt = -W-/(2b) = -9.8236e-5/0.68
  //   yt = W+ D/(2 b^2) = 1.04964e-3/0.2312     tt = W+/b^2 = 1.04964e-4/0.1156
  Cov3 p{};
  propagate_arc_slip(p, 0.0, 1.0, 10.0, 10.0, kB, kParams, 1e-4, 0.0);
  EXPECT_NEAR(p[XX], 2.6241e-5, 1e-19);
  EXPECT_NEAR(p[YY], 1.04964e-2 / 0.3468, 1e-15);
  EXPECT_NEAR(p[XY], -9.8236e-4 / 1.36, 1e-17);
  EXPECT_NEAR(p[XT], -9.8236e-5 / 0.68, 1e-18);
  EXPECT_NEAR(p[YT], 1.04964e-3 / 0.2312, 1e-16);
  EXPECT_NEAR(p[TT], 1.04964e-4 / 0.1156, 1e-17);
  // No extra variance: propagate_arc's (its tiered series may differ in the last bits).
  Cov3 a{}, b{};
  propagate_arc_slip(a, std::sin(0.3), std::cos(0.3), 1.0, 1.2, kB, kParams, 0.0, 0.0);
  propagate_arc(b, 0.3, 1.0, 1.2, kB, kParams);
  expect_cov_near(a, b, 1e-14, "slip without extra variance");
}

TEST(ErrorModel, SlipTravelVarianceTelescopesToTheIntervalsSpreadSquared) {
  // Spreads 3, 1, 2 mm over three ticks: v = 3 (0 + 3) = 9, 1 (2 * 3 + 1) = 7, 2 (2 * 4 + 2) =
  // 20 [mm^2]: 36 = (3 + 1 + 2)^2, the variance of the interval's whole 6 mm.
  double s = 0.0;
  EXPECT_DOUBLE_EQ(slip_travel_variance(s, 3e-3), 9e-6);
  EXPECT_DOUBLE_EQ(slip_travel_variance(s, 1e-3), 7e-6);
  EXPECT_DOUBLE_EQ(slip_travel_variance(s, 2e-3), 20e-6);
  EXPECT_DOUBLE_EQ(s, 6e-3);
}

TEST(ErrorModel, StraightLineRotatedByHeading) {
  // The same 10 m along heading 90 deg: x and y swap roles (R = [0 -1; 1 0]):
  //   xx' = yy, yy' = xx, xy' = -xy, xt' = -yt, yt' = xt, tt' = tt.
  Cov3 p0{}, p90{};
  propagate_arc(p0, 0.0, 10.0, 10.0, kB, kParams);
  propagate_arc(p90, kPi / 2, 10.0, 10.0, kB, kParams);
  EXPECT_NEAR(p90[XX], p0[YY], 1e-15 * p0[YY]);
  EXPECT_NEAR(p90[YY], p0[XX], 1e-12 * p0[XX]);
  EXPECT_NEAR(p90[XY], -p0[XY], 1e-12 * std::fabs(p0[XY]));
  EXPECT_NEAR(p90[XT], -p0[YT], 1e-15 * p0[YT]);
  EXPECT_NEAR(p90[YT], p0[XT], 1e-12 * p0[XT]);
  EXPECT_DOUBLE_EQ(p90[TT], p0[TT]);
}

TEST(ErrorModel, OnTheSpotHalfTurnHandValues) {
  // d_L = -b pi/2, d_R = +b pi/2: phi = pi, D = 0. With b = 0.34: |d| = 0.17 pi each,
  // w_L = 1.6e-7 * 0.17 pi, w_R = 3.364e-7 * 0.17 pi. At phi = pi: I_cc = I_ss = 1/2, I_cs = 0,
  // I_c = sin(pi)/pi = 0, I_s = (1 - cos pi)/pi = 2/pi. On-the-spot limit:
  //   xx = W+ I_cc/4 = W+/8, yy = W+/8, xy = 0, xt = -W- I_c/(2b) = 0,
  //   yt = -W- I_s/(2b) = -W-/(pi b), tt = W+/b^2.
  const double wl = 1.6e-7 * 0.17 * kPi, wr = 3.364e-7 * 0.17 * kPi;
  const double wp = wl + wr, wm = wl - wr;
  Cov3 p{};
  propagate_arc(p, 0.0, -kB * kPi / 2, kB * kPi / 2, kB, kParams);
  EXPECT_NEAR(p[XX], wp / 8, 1e-15 * wp);
  EXPECT_NEAR(p[YY], wp / 8, 1e-15 * wp);
  EXPECT_NEAR(p[XY], 0.0, 1e-15 * wp);
  EXPECT_NEAR(p[XT], 0.0, 1e-15 * wp);
  EXPECT_NEAR(p[YT], -wm / (kPi * kB), 1e-15 * wp);
  EXPECT_NEAR(p[TT], wp / (kB * kB), 1e-14 * wp);
}

TEST(ErrorModel, QuarterCircleHandValues) {
  // Left quarter circle of centre radius 1 m (the ArcStep test's wheels): d_L = 0.83 pi/2,
  // d_R = 1.17 pi/2, phi = pi/2, D = pi/2, a = D/b = pi/0.68. At phi = pi/2 (S = 1, C = 0):
  //   I_c = I_s = 2/pi, I_cc = I_ss = 1/2, I_cs = 1/pi, J_x = (2 pi - 4)/pi^2, J_y = 4/pi^2,
  //   J_xx = (3/2 - 4/pi) 4/pi^2, J_yy = 2/pi^2, J_xy = 4/pi^3, J_cx = J_sy = 2/pi^2,
  //   J_cy = 1/pi, J_sx = (4 - pi)/pi^2.
  const double pi = kPi, pi2 = pi * pi;
  const ArcTerms t = arc_terms(pi / 2);
  EXPECT_NEAR(t.i_c, 2 / pi, 1e-15);
  EXPECT_NEAR(t.i_s, 2 / pi, 1e-15);
  EXPECT_NEAR(t.i_cc, 0.5, 1e-15);
  EXPECT_NEAR(t.i_ss, 0.5, 1e-15);
  EXPECT_NEAR(t.i_cs, 1 / pi, 1e-15);
  EXPECT_NEAR(t.j_x, (2 * pi - 4) / pi2, 1e-15);
  EXPECT_NEAR(t.j_y, 4 / pi2, 1e-15);
  EXPECT_NEAR(t.j_xx, (1.5 - 4 / pi) * 4 / pi2, 1e-15);
  EXPECT_NEAR(t.j_yy, 2 / pi2, 1e-15);
  EXPECT_NEAR(t.j_xy, 4 / (pi2 * pi), 1e-15);
  EXPECT_NEAR(t.j_cx, 2 / pi2, 1e-15);
  EXPECT_NEAR(t.j_sy, 2 / pi2, 1e-15);
  EXPECT_NEAR(t.j_cy, 1 / pi, 1e-15);
  EXPECT_NEAR(t.j_sx, (4 - pi) / pi2, 1e-15);

  // Assemble by hand: w_L = 1.6e-7 * 0.83 pi/2, w_R = 3.364e-7 * 1.17 pi/2.
  const double wl = 1.6e-7 * 0.83 * pi / 2, wr = 3.364e-7 * 1.17 * pi / 2;
  const double wp = wl + wr, wm = wl - wr, a = (pi / 2) / kB;
  const double xx = wp * (0.5 / 4 + a * a * 2 / pi2) + wm * a / pi;
  const double yy = wp * (0.5 / 4 + a * a * (1.5 - 4 / pi) * 4 / pi2) - wm * a * (4 - pi) / pi2;
  const double xy = wp * (1 / (4 * pi) - a * a * 4 / (pi2 * pi)) + 0.5 * wm * a * 0.0;
  const double xt = -(wp * a * 4 / pi2 + 0.5 * wm * 2 / pi) / kB;
  const double yt = (wp * a * (2 * pi - 4) / pi2 - 0.5 * wm * 2 / pi) / kB;
  const Cov3 q = arc_input_covariance(0.83 * pi / 2, 1.17 * pi / 2, kB, kParams);
  const Cov3 hand{xx, xy, xt, xy, yy, yt, xt, yt, wp / (kB * kB)};
  expect_cov_near(q, hand, 1e-14, "quarter circle");
}

TEST(ErrorModel, SeriesAndClosedFormsMeetAtTheSwitch) {
  // |phi| = 1 switches from the Taylor series to the closed forms; both sides must agree.
  for (double sign : {1.0, -1.0}) {
    const ArcTerms lo = arc_terms(sign * std::nextafter(1.0, 0.0));
    const ArcTerms hi = arc_terms(sign * 1.0);
    const double* a = &lo.i_c;
    const double* b = &hi.i_c;
    for (std::size_t i = 0; i < sizeof(ArcTerms) / sizeof(double); ++i) {
      EXPECT_NEAR(a[i], b[i], 4e-15 * std::fabs(b[i])) << "term " << i << " sign " << sign;
    }
  }
}

TEST(ErrorModel, ShortAndFullSeriesMeetAtTheSwitches) {
  // |phi| = 0.015 switches from the four-term series (ticks below 15 rad/s at 1 kHz) to the
  // six-term one, |phi| = 0.05 from that to the full series. The omitted terms are below 2^-60
  // (8e-19) of the leading one at either switch, so both sides agree to rounding.
  for (double at : {0.015, 0.05}) {
    for (double sign : {1.0, -1.0}) {
      const ArcTerms lo = arc_terms(sign * std::nextafter(at, 0.0));
      const ArcTerms hi = arc_terms(sign * at);
      const double* a = &lo.i_c;
      const double* b = &hi.i_c;
      for (std::size_t i = 0; i < sizeof(ArcTerms) / sizeof(double); ++i) {
        EXPECT_NEAR(a[i], b[i], 4e-15 * std::fabs(b[i])) << "term " << i << " at " << sign * at;
      }
    }
  }
}

TEST(ErrorModel, SineCosineEntryEqualsHeadingEntry) {
  // The loop passes the integrator's cached sin/cos of the start heading instead of the angle;
  // from any starting covariance both entries must give the same result (to rounding).
  for (double theta0 : {0.0, 0.3, 2.0, -2.9, 7.5}) {
    Cov3 a{1e-4, 2e-5, -3e-5, 2e-5, 5e-4, 1e-5, -3e-5, 1e-5, 2e-4};
    Cov3 b = a;
    propagate_arc(a, theta0, 0.011, 0.0102, kB, kParams);
    propagate_arc(b, std::sin(theta0), std::cos(theta0), 0.011, 0.0102, kB, kParams);
    expect_cov_near(b, a, 1e-14, "sin/cos entry");
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) EXPECT_EQ(b[3 * i + j], b[3 * j + i]) << "not symmetric";
    }
  }
}

TEST(ErrorModel, ZeroTurnLimits) {
  // phi = 0: I_c = 1, I_s = 0, I_cc = 1, I_ss = 0, I_cs = 0, J_x = int (1-u) = 1/2, J_y = 0,
  // J_xx = int (1-u)^2 = 1/3, J_yy = J_xy = 0, J_cx = 1/2, J_cy = J_sx = J_sy = 0.
  const ArcTerms t = arc_terms(0.0);
  EXPECT_EQ(t.i_c, 1.0);
  EXPECT_EQ(t.i_s, 0.0);
  EXPECT_EQ(t.i_cc, 1.0);
  EXPECT_EQ(t.i_ss, 0.0);
  EXPECT_EQ(t.j_x, 0.5);
  EXPECT_NEAR(t.j_xx, 1.0 / 3.0, 1e-16);
  EXPECT_EQ(t.j_cx, 0.5);
  EXPECT_EQ(t.j_yy, 0.0);
  EXPECT_EQ(t.j_sx, 0.0);
}

struct Case {
  const char* name;
  double d_left, d_right, theta0;
};

const std::vector<Case> kCases = {
    {"straight", 10.0, 10.0, 0.3},
    {"straight backwards", -10.0, -10.0, -1.0},
    {"near straight", 10.0, 10.0 + 1e-9, 0.0},
    {"gentle arc", 5.0, 5.2, 2.0},
    {"right arc of 540 deg", 1.17 * 3 * kPi, 0.83 * 3 * kPi, 0.0},
    {"on the spot", -0.5, 0.5, 0.0},
    {"near on the spot", -0.5, 0.5 + 1e-10, 1.0},
    {"one wheel still", 0.0, 2.0, 0.0},
    {"wheels opposite, unequal", -0.3, 1.1, -0.5},
    {"many turns", 30.0, 60.0, 0.0},
    {"tiny", 1e-9, 1.1e-9, 0.0},
};

TEST(ErrorModel, OneSegmentEqualsThousandPieces) {
  // Consistency (Sec. 4): the same arc in one step or cut into 1000 equal ticks gives the same
  // covariance, because the closed form is itself the limit of infinitely many pieces.
  for (const Case& c : kCases) {
    Cov3 one{}, many{};
    propagate_arc(one, c.theta0, c.d_left, c.d_right, kB, kParams);
    Pose2 pose{0.0, 0.0, c.theta0};
    const int n = 1000;
    for (int i = 0; i < n; ++i) {
      propagate_arc(many, pose.theta, c.d_left / n, c.d_right / n, kB, kParams);
      pose = arc_step(pose, c.d_left / n, c.d_right / n, kB);
    }
    expect_cov_near(many, one, 1e-9, c.name);
  }
}

TEST(ErrorModel, ConsistentAcrossUnequalPieces) {
  // A path of two different arcs, cut into uneven pieces, against the two arcs in one step each.
  Cov3 coarse{}, fine{};
  Pose2 pose{};
  const double segs[2][2] = {{4.0, 4.6}, {-2.0, -1.0}};
  for (const auto& s : segs) {
    propagate_arc(coarse, pose.theta, s[0], s[1], kB, kParams);
    pose = arc_step(pose, s[0], s[1], kB);
  }
  pose = {};
  for (const auto& s : segs) {
    double done = 0.0;
    for (int i = 1; done < 1.0; ++i) {
      const double frac = std::min(1.0 - done, 1e-3 * (1 + i % 7));  // 1..7 thousandths
      propagate_arc(fine, pose.theta, s[0] * frac, s[1] * frac, kB, kParams);
      pose = arc_step(pose, s[0] * frac, s[1] * frac, kB);
      done += frac;
    }
  }
  expect_cov_near(fine, coarse, 1e-9, "two arcs, uneven pieces");
}

// dsinc: derivative of sin(x)/x.
double dsinc(double x) {
  if (std::fabs(x) < 1e-2) return -x / 3.0 + x * x * x / 30.0;  // next term x^5/840 < 1e-13
  return (x * std::cos(x) - std::sin(x)) / (x * x);
}

// brute_force: Eq. 15 evaluated literally with n discrete steps of the exact arc of Eq. 13
// (odo::arc_step, the firmware's pose code: chord D sinc(phi/2) along the mean heading
// m = theta + phi/2), the state Jacobian [1 0 -dy; 0 1 dx; 0 0 1] of each step, the analytic
// input Jacobian of each step, and Cov(u_i) = diag(k_L^2 |L_i|, k_R^2 |R_i|). With
// D = (L + R)/2 and phi = (R - L)/b: d/dL = d/dD /2 - d/dphi / b, d/dR = d/dD /2 + d/dphi / b,
//   dx/dD = sinc cos m, dy/dD = sinc sin m, dtheta/dD = 0,
//   dx/dphi = D sinc' cos m /2 - chord sin m /2, dy/dphi = D sinc' sin m /2 + chord cos m /2,
//   dtheta/dphi = 1.
Cov3 brute_force(const Case& c, int n) {
  using M3 = Eigen::Matrix3d;
  M3 p = M3::Zero();
  Pose2 pose{0.0, 0.0, c.theta0};
  const double l = c.d_left / n, r = c.d_right / n;
  const double d = 0.5 * (l + r), phi = (r - l) / kB;
  const double sinc = phi == 0.0 ? 1.0 : std::sin(phi / 2) / (phi / 2);
  const double chord = d * sinc;
  for (int i = 0; i < n; ++i) {
    const Pose2 next = arc_step(pose, l, r, kB);
    M3 f = M3::Identity();
    f(0, 2) = -(next.y - pose.y);
    f(1, 2) = next.x - pose.x;
    const double cm = std::cos(pose.theta + phi / 2), sm = std::sin(pose.theta + phi / 2);
    const Eigen::Vector3d by_d(sinc * cm, sinc * sm, 0.0);
    const Eigen::Vector3d by_phi(d * dsinc(phi / 2) * cm / 2 - chord * sm / 2,
                                 d * dsinc(phi / 2) * sm / 2 + chord * cm / 2, 1.0);
    Eigen::Matrix<double, 3, 2> g;
    g.col(0) = by_d / 2 - by_phi / kB;
    g.col(1) = by_d / 2 + by_phi / kB;
    Eigen::Matrix2d cu = Eigen::Matrix2d::Zero();
    cu(0, 0) = kL * kL * std::fabs(l);
    cu(1, 1) = kR * kR * std::fabs(r);
    p = f * p * f.transpose() + g * cu * g.transpose();
    pose = next;
  }
  Cov3 out;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) out[3 * i + j] = p(i, j);
  return out;
}

// worst_rel: largest |a_ij - b_ij| / sqrt(b_ii b_jj).
double worst_rel(const Cov3& a, const Cov3& b) {
  double w = 0.0;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      w = std::max(w, std::fabs(a[3 * i + j] - b[3 * i + j]) / std::sqrt(b[4 * i] * b[4 * j]));
  return w;
}

TEST(ErrorModel, AgreesWithBruteForceJacobianPropagation) {
  // The discrete sum of Eq. 15/16 converges to the closed form like 1/n^2 (each step's curvature
  // is exact; that a step's noise acts at its start rather than along it is the error). At
  // n = 80000 steps every entry agrees to 1e-7 of its scale, and going from 20000 to 80000 steps
  // shrinks the difference about 16-fold wherever it is above round-off.
  for (const Case& c : kCases) {
    if (std::fabs(c.d_left) + std::fabs(c.d_right) < 1e-6) continue;  // nothing to resolve
    Cov3 closed{};
    propagate_arc(closed, c.theta0, c.d_left, c.d_right, kB, kParams);
    const double e20 = worst_rel(brute_force(c, 20000), closed);
    const double e80 = worst_rel(brute_force(c, 80000), closed);
    EXPECT_LT(e80, 1e-7) << c.name;
    if (e20 > 1e-8) {
      EXPECT_GT(e20 / e80, 10.0) << c.name << ": " << e20 << " -> " << e80;
    }
  }
}

TEST(ErrorModel, FiniteAndPositiveSemidefiniteEverywhere) {
  // Tiny, huge, equal, opposite, nearly equal and nearly opposite travels, zero, denormal: never
  // NaN or infinity, and the covariance stays positive semidefinite.
  const double vals[] = {0.0, 1e-300, -1e-300, 1e-12, -1e-12, 1e-6, 0.01, -0.01, 0.17,
                         0.5, -0.5,   1.0,     -1.0,  3.0,    1e3,  -1e3, 1e6,   -1e6};
  const double nudges[] = {0.0, 1e-15, -1e-12, 1e-8};
  for (double l : vals) {
    for (double r : vals) {
      for (double e : nudges) {
        Cov3 p{};
        propagate_arc(p, 0.7, l, r + e, kB, kParams);
        propagate_arc(p, 1e6, r, l - e, kB, kParams);  // a second tick at a huge heading
        Eigen::Matrix3d m;
        for (int i = 0; i < 9; ++i) {
          ASSERT_TRUE(std::isfinite(p[i])) << l << " " << r << " " << e;
          m(i / 3, i % 3) = p[i];
        }
        const Eigen::Vector3d ev = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(m).eigenvalues();
        EXPECT_GE(ev(0), -1e-12 * std::max(ev(2), 1e-300)) << l << " " << r << " " << e;
      }
    }
  }
  Cov3 p{};
  propagate_arc(p, 0.0, std::nan(""), 1.0, kB, kParams);
  propagate_arc(p, 0.0, 1.0, INFINITY, kB, kParams);
  propagate_arc(p, 0.0, 1.0, 1.0, 0.0, kParams);
  for (double v : p) EXPECT_EQ(v, 0.0);
}

TEST(ErrorModel, StraightLineLateralCubicAlongTrackLinear) {
  // Integrated tick by tick (1 mm ticks) as the loop does: lateral variance ~ D^3, along-track
  // ~ D (Sec. 4.1). Fitted log-log slopes over 0.5 .. 16 m must be within 2% of 3 and 1.
  Cov3 p{};
  std::vector<double> dist, lateral, along;
  const double tick = 1e-3;
  long ticks = 0;
  for (double target : {0.5, 1.0, 2.0, 4.0, 8.0, 16.0}) {
    while (static_cast<double>(ticks) * tick < target - 1e-9) {
      propagate_arc(p, 0.0, tick, tick, kB, kParams);
      ++ticks;
    }
    dist.push_back(target);
    along.push_back(p[XX]);
    lateral.push_back(p[YY]);
  }
  EXPECT_NEAR(test::loglog_slope(dist, lateral), 3.0, 0.02 * 3.0);
  EXPECT_NEAR(test::loglog_slope(dist, along), 1.0, 0.02 * 1.0);
}

TEST(ErrorModel, ParameterRanges) {
  EXPECT_TRUE(check_error_model({0.0004, 0.00058}));
  EXPECT_TRUE(check_error_model({0.0, 0.1}));
  auto bad = check_error_model({-1e-4, 0.00058});
  ASSERT_FALSE(bad);
  EXPECT_NE(bad.error().message.find("k_left = -0.0001"), std::string::npos);
  EXPECT_NE(bad.error().message.find("[0, 0.1]"), std::string::npos);
  EXPECT_FALSE(check_error_model({0.0004, std::nan("")}));
  EXPECT_FALSE(check_error_model({0.0004, 0.2}));
  EXPECT_TRUE(check_error_model({0.0004, 0.00058, 100}));
  auto ticks = check_error_model({0.0004, 0.00058, 0});
  ASSERT_FALSE(ticks);
  EXPECT_NE(
      ticks.error().message.find("covariance_ticks = 0 is outside the allowed range [1, 100]"),
      std::string::npos)
      << ticks.error().message;
  EXPECT_FALSE(check_error_model({0.0004, 0.00058, 101}));
}

TEST(PoseCovariance, ResetZeroes) {
  PoseCovariance pc(kParams);
  pc.step(0.0, 1.0, 1.1, kB);
  EXPECT_GT(pc.cov()[TT], 0.0);
  pc.reset();
  for (double v : pc.cov()) EXPECT_EQ(v, 0.0);
}

// drive: n ticks of wheel travels (dl, dr) [m] through pc as the loop's Odometry does (the pose
// integrator's start heading and its (d_R - d_L) / b as phi).
void drive(PoseCovariance& pc, PoseIntegrator& pose, int n, double dl, double dr) {
  for (int i = 0; i < n; ++i) {
    const double s0 = pose.sin_theta(), c0 = pose.cos_theta(), phi = (dr - dl) / kB;
    pose.step_arc(0.5 * (dl + dr), phi);
    pc.step_sc_phi(s0, c0, dl, dr, kB, phi);
  }
}

TEST(PoseCovarianceMerged, StraightLineInGroupsHasTheHandValues) {
  // The hand values of StraightLineHandValues (D = 10 m, b = 0.34 m), driven as 1000 ticks of
  // 1 cm merged ten at a time: 100 arcs of 0.1 m. The closed form is consistent, so the sum of
  // the pieces is the whole; the tolerance is the rounding of 100 sums (a few ulp each).
  PoseCovariance pc({kL, kR, 10});
  PoseIntegrator pose;
  drive(pc, pose, 1000, 0.01, 0.01);
  EXPECT_EQ(pc.pending_ticks(), 0u);
  const Cov3& p = pc.cov();
  EXPECT_NEAR(p[XX], 1.241e-6, 1e-12 * 1.241e-6);
  EXPECT_NEAR(p[YY], 4.964e-4 / 0.3468, 1e-12 * 4.964e-4 / 0.3468);
  EXPECT_NEAR(p[XY], 1.764e-5 / 1.36, 1e-12 * 1.764e-5 / 1.36);
  EXPECT_NEAR(p[XT], 1.764e-6 / 0.68, 1e-12 * 1.764e-6 / 0.68);
  EXPECT_NEAR(p[YT], 4.964e-5 / 0.2312, 1e-12 * 4.964e-5 / 0.2312);
  EXPECT_NEAR(p[TT], 4.964e-6 / 0.1156, 1e-12 * 4.964e-6 / 0.1156);
}

TEST(PoseCovarianceMerged, ArcInGroupsEqualsArcTickByTick) {
  // A constant-curvature arc (d_R / d_L = 1.1, 2000 ticks, 0.59 rad): any grouping of its ticks
  // is the same arc cut into other pieces, so the covariance is the same to rounding.
  PoseCovariance one(kParams), grouped({kL, kR, 7});  // 7: groups that end mid-run, 2000 = 7*285+5
  PoseIntegrator p1, p2;
  drive(one, p1, 2000, 0.001, 0.0011);
  drive(grouped, p2, 2000, 0.001, 0.0011);
  EXPECT_EQ(grouped.pending_ticks(), 5u);
  grouped.flush();
  EXPECT_EQ(grouped.pending_ticks(), 0u);
  expect_cov_near(grouped.cov(), one.cov(), 1e-11, "arc");
}

TEST(PoseCovarianceMerged, LagsByThePendingTicksAndResetDropsThem) {
  // Nine ticks of ten: none propagated yet; the tenth propagates the group.
  PoseCovariance pc({kL, kR, 10});
  PoseIntegrator pose;
  drive(pc, pose, 9, 0.01, 0.01);
  EXPECT_EQ(pc.pending_ticks(), 9u);
  for (double v : pc.cov()) EXPECT_EQ(v, 0.0);
  drive(pc, pose, 1, 0.01, 0.01);
  EXPECT_EQ(pc.pending_ticks(), 0u);
  EXPECT_GT(pc.cov()[TT], 0.0);
  // A set pose is exact: the pending ticks belong to the pose it replaced.
  drive(pc, pose, 4, 0.01, 0.01);
  pc.reset();
  EXPECT_EQ(pc.pending_ticks(), 0u);
  pc.flush();
  for (double v : pc.cov()) EXPECT_EQ(v, 0.0);
}

TEST(PoseCovarianceMerged, AReversingWheelClosesTheGroup) {
  // 5 cm forward then 5 cm back, 1 cm a tick, groups of 10. Summed over the reversal the travels
  // would cancel (no variance at all); closed at it, each straight half is its own arc, as tick by
  // tick: tt = (k_L^2 + k_R^2) * 0.1 m / b^2 = 4.964e-8 / 0.1156.
  PoseCovariance one(kParams), grouped({kL, kR, 10});
  PoseIntegrator p1, p2;
  for (auto* g : {&one, &grouped}) {
    PoseIntegrator& p = g == &one ? p1 : p2;
    drive(*g, p, 5, 0.01, 0.01);
    drive(*g, p, 5, -0.01, -0.01);
  }
  grouped.flush();
  EXPECT_NEAR(grouped.cov()[TT], 4.964e-8 / 0.1156, 1e-12 * 4.964e-8 / 0.1156);
  expect_cov_near(grouped.cov(), one.cov(), 1e-12, "reversal");
}

TEST(PoseCovarianceMerged, RoundedCornersInGroupsStayWithinThreeMillionths) {
  // A square with rounded corners at 1 kHz: 4 m sides at 0.2 m/s (0.2 mm a tick) and quarter
  // turns on arcs (0.1 and 0.3 mm a tick: phi = 0.2 mm / b = 5.9e-4 rad a tick, 2670 ticks),
  // in groups of 10. No wheel reverses, so a group that spans a corner's start or end is taken
  // as one arc although its curvature changes inside it: eight such groups in 17 m. Each moves
  // part of 10 ticks' noise by a fraction of 10 ticks' heading change (5.9e-3 rad), against the
  // whole path's covariance: measured 2.8e-7 of the scale (entry x-y, 1.8e-10 m^2 of 6.5e-4); the
  // bound is ten times that.
  PoseCovariance one(kParams), grouped({kL, kR, 10});
  PoseIntegrator p1, p2;
  for (auto* g : {&one, &grouped}) {
    PoseIntegrator& p = g == &one ? p1 : p2;
    for (int side = 0; side < 4; ++side) {
      drive(*g, p, 20003, 0.0002, 0.0002);  // 20003: the corners fall inside groups
      drive(*g, p, 2670, 0.0001, 0.0003);
    }
  }
  grouped.flush();
  expect_cov_near(grouped.cov(), one.cov(), 3e-6, "rounded square");
}

TEST(ErrorModel, TwistCovarianceOfTheWheelsHandValues) {
  // kL = 0.001, kR = 0.002, dL = 0.01 m, dR = -0.04 m over dt = 0.1 s, b = 0.5 m:
  // wL = 1e-6 * 0.01 = 1e-8, wR = 4e-6 * 0.04 = 1.6e-7 (|d|: the sign is irrelevant),
  // wL + wR = 1.7e-7. var v = 1.7e-7 / (4 * 0.01) = 4.25e-6; var omega = 1.7e-7 / (0.25 * 0.01)
  // = 6.8e-5; cov = (1.6e-7 - 1e-8) / (2 * 0.5 * 0.01) = 1.5e-5.
  ErrorModelParams k;
  k.k_left = 0.001;
  k.k_right = 0.002;
  const Cov2 c = twist_covariance(TickMotion{0.01, -0.04, 0.1, 0.5}, k);
  EXPECT_NEAR(c[0], 4.25e-6, 1e-18);
  EXPECT_NEAR(c[3], 6.8e-5, 1e-17);
  EXPECT_NEAR(c[1], 1.5e-5, 1e-18);
  EXPECT_EQ(c[1], c[2]);
  const Cov2 zero = twist_covariance(TickMotion{0.0, 0.0, 0.1, 0.5}, k);
  EXPECT_EQ(zero[0], 0.0);
  EXPECT_EQ(zero[3], 0.0);
  // Nothing measured (no interval, no wheelbase): zero, not a division by zero.
  EXPECT_EQ(twist_covariance(TickMotion{0.01, 0.01, 0.0, 0.5}, k)[0], 0.0);
  EXPECT_EQ(twist_covariance(TickMotion{0.01, 0.01, 0.1, 0.0}, k)[3], 0.0);
}

TEST(ErrorModel, TwistCovarianceOfAGyroTickTakesOmegaFromTheGyro) {
  // The same wheels with the heading from the gyro, var_heading = 4e-8 rad^2 over dt = 0.1 s:
  // var v is the wheels' 4.25e-6 as before; var omega = 4e-8 / 0.01 = 4e-6; the gyro's noise
  // is independent of the wheels': cov = 0.
  ErrorModelParams k;
  k.k_left = 0.001;
  k.k_right = 0.002;
  TickMotion m{0.01, -0.04, 0.1, 0.5};
  m.gyro_heading = true;
  m.gyro_var_heading = 4e-8;
  const Cov2 c = twist_covariance(m, k);
  EXPECT_NEAR(c[0], 4.25e-6, 1e-18);
  EXPECT_NEAR(c[3], 4e-6, 1e-19);
  EXPECT_EQ(c[1], 0.0);
  EXPECT_EQ(c[2], 0.0);
}

// Skid steer (x_icr != 0): the analytic covariance of Odometry::advance_travel against a Monte
// Carlo of the same step. Path: 2000 ticks of d_L = -0.2 mm, d_R = +0.6 mm on b = 0.5 m
// (0.4 m forward, 3.2 rad of turn), x_icr = 0.2 m, so the sideways slide (-x_icr dtheta, 0.64 m
// in all) is larger than the forward travel. Each run draws each tick's wheel noise
// N(0, k^2 |d|) (Eq. 4 per tick) and integrates the noisy travels with the same step; the
// sample covariance of the end poses against the one analytic propagation of the noise-free
// travels. 4000 runs: a sample variance's relative standard error is sqrt(2/3999) = 2.2 %, the
// 10 % bound 4.5 of them (the first-order model's own bias on a 3.2 rad path is a few %).
struct McCov {
  Cov3 analytic{};
  Cov3 plain{};  // the plain model's (x_icr = 0) covariance of the same travels
  Cov3 sample{};
};

McCov skid_monte_carlo(double x_icr) {
  constexpr int kTicks = 2000, kRuns = 4000;
  constexpr double dl = -0.0002, dr = 0.0006, b = 0.5, k = 0.002;
  const ErrorModelParams em{k, k};
  KinematicParams p{0.15, 2048, 16, b, b, 1.0, 1.0};
  p.x_icr = x_icr;
  const Kinematics kin = *Kinematics::create(p);
  McCov out;
  Odometry analytic(kin, em);
  for (int i = 0; i < kTicks; ++i) analytic.advance_travel(dl, dr, 0.001);
  out.analytic = analytic.covariance();
  p.x_icr = 0.0;
  Odometry plain(*Kinematics::create(p), em);
  for (int i = 0; i < kTicks; ++i) plain.advance_travel(dl, dr, 0.001);
  out.plain = plain.covariance();
  std::mt19937_64 rng(1);
  std::normal_distribution<double> n_l(0.0, k * std::sqrt(std::fabs(dl)));
  std::normal_distribution<double> n_r(0.0, k * std::sqrt(std::fabs(dr)));
  std::vector<std::array<double, 3>> ends;
  std::array<double, 3> mean{};
  for (int r = 0; r < kRuns; ++r) {
    Odometry o(kin, em);
    for (int i = 0; i < kTicks; ++i) o.update_travel(dl + n_l(rng), dr + n_r(rng), 0.001);
    const std::array<double, 3> end{o.pose().x, o.pose().y, o.pose().theta};
    ends.push_back(end);
    for (int j = 0; j < 3; ++j) mean[j] += end[j] / kRuns;
  }
  for (const auto& e : ends) {
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) {
        out.sample[3 * i + j] += (e[i] - mean[i]) * (e[j] - mean[j]) / (kRuns - 1);
      }
    }
  }
  return out;
}

TEST(ErrorModelIcr, AnalyticCovarianceMatchesMonteCarloOfTheSkidStep) {
  const McCov c = skid_monte_carlo(0.2);
  for (int i = 0; i < 3; ++i) {
    const double a = c.analytic[4 * i], s = c.sample[4 * i];
    EXPECT_LT(std::fabs(a - s) / s, 0.10)
        << "variance " << i << ": analytic " << a << " sample " << s;
  }
  // Correlations too (each entry against the scale of its two variances).
  for (int e : {1, 2, 5}) {
    const double scale = std::sqrt(c.sample[4 * (e / 3)] * c.sample[4 * (e % 3)]);
    EXPECT_LT(std::fabs(c.analytic[e] - c.sample[e]) / scale, 0.10) << "entry " << e;
  }
  // The test can tell: the plain model's covariance of the same travels misses the slide's
  // share of the position variance.
  double worst = 0.0;
  for (int i = 0; i < 2; ++i) {
    worst = std::max(worst, std::fabs(c.plain[4 * i] - c.sample[4 * i]) / c.sample[4 * i]);
  }
  EXPECT_GT(worst, 0.3) << "the plain covariance is as good: the test would not see the ICR term";
}

}  // namespace
}  // namespace odo
