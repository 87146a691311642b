#include "odo/odometry/error_model.hpp"

#include <Eigen/Core>
#include <cmath>
#include <string>

// Derivation (Chong & Kleeman Sec. 4; our own notation, checked against brute-force per-step
// Jacobian propagation in tests/unit/test_error_model.cpp).
//
// Take one arc in the frame of its start pose: heading theta(u) = phi u, centre travel D u for
// the arc parameter u in [0, 1], with D = (d_L + d_R) / 2 and phi = (d_R - d_L) / b. Cut it into
// k pieces of du (Eq. 15). A piece's wheel noise dL, dR (variances k_L^2 |d_L| du, k_R^2 |d_R| du,
// Eq. 4) moves the pose by G = [c/2, c/2; s/2, s/2; -1/b, 1/b] (c, s = cos, sin of phi u); the
// state Jacobians of all later pieces multiply to [1 0 -Y; 0 1 X; 0 0 1], where (X, Y) is the
// displacement still to come, X = D X^(u) = D int_u^1 cos(phi t) dt, Y = D Y^(u) = D int_u^1 sin.
// So the left wheel's noise reaches the end of the arc through a_L = p + q and the right one's
// through a_R = p - q, with p = (c/2, s/2, 0) and q = (Y/b, -X/b, -1/b). For k -> infinity the sum
// of Eq. 16 becomes an integral:
//   Cov(U) = int_0^1 (w_L a_L a_L^T + w_R a_R a_R^T) du
//          = W+ int (p p^T + q q^T) du + W- int (p q^T + q p^T) du,
//   w_L = k_L^2 |d_L|, w_R = k_R^2 |d_R|, W+ = w_L + w_R, W- = w_L - w_R.
// With a = D / b, entry by entry:
//   xx = W+ (I_cc/4 + a^2 J_yy) + W- a J_cy          yy = W+ (I_ss/4 + a^2 J_xx) - W- a J_sx
//   xy = W+ (I_cs/4 - a^2 J_xy) + W- a (J_sy - J_cx)/2
//   tt = W+ / b^2     xt = -(W+ a J_y + W- I_c/2) / b     yt = (W+ a J_x - W- I_s/2) / b
// where I_f = int_0^1 f du and J_f = int_0^1 f du with X^, Y^ in place of X, Y. This is the
// quantity of Eq. 17; we derive it ourselves because the seed text of Eq. 17/18 lost factors in
// conversion (its Cov_33 = c3/B^2 is not even dimensionless), and we write it with D and phi
// instead of r = D/phi and (L - R) denominators, so the straight-line (phi -> 0) and on-the-spot
// (D -> 0) limits need no division by zero:
//   straight line: xx = W+/4, yy = W+ D^2/(3 b^2), xy = -W- D/(4b), xt = -W-/(2b),
//                  yt = W+ D/(2 b^2), tt = W+/b^2 (along-track ~ D, lateral ~ D^3);
//   on the spot:   xx = W+ I_cc/4, yy = W+ I_ss/4, xy = W+ I_cs/4, xt = -W- I_c/(2b),
//                  yt = -W- I_s/(2b), tt = W+/b^2.
// Closed forms (S, C = sin, cos of phi; h = (1 - C)/phi^2):
//   I_c = S/phi, I_s = phi h, I_ss = (phi - S C)/(2 phi), I_cc = 1 - I_ss, I_cs = S^2/(2 phi),
//   J_x = I_c - h, J_y = (S - phi C)/phi^2, J_xx = (S^2 - 2 S I_s + I_ss)/phi^2,
//   J_yy = (1/2 + C^2 - 3 S C/(2 phi))/phi^2, J_xy = (S^2/(2 phi) - S C + C (1 - C)/phi)/phi^2,
//   J_cx = I_c^2/2, J_cy = I_ss/phi, J_sy = I_s^2/2, J_sx = I_c I_s - J_cy.
// Several of them cancel catastrophically as phi -> 0 (J_yy ~ 2 phi^2/15 out of O(1) terms), so
// below |phi| = 1 the seven basic functions are evaluated from their Taylor series instead.
//
// Slip (several encoders per side, hal/side_wheels.hpp). While the wheels of a side disagree
// beyond the slip threshold, the side's travel (their mean) is uncertain by about their spread:
// a spinning wheel over-counts by up to the spread, and which wheel is right is not known. That
// error is not white: a wheel that spins errs the same way on every tick of the interval, so
// over an interval of total spread S the side's travel is off by up to S, variance ~S^2, not the
// sum of the ticks' squares (which would shrink it by the number of ticks). Each tick k of the
// interval adds the extra variance v_k = S_k^2 - S_(k-1)^2 = s_k (2 S_(k-1) + s_k) to its side's
// wheel (S_k the spread up to and including tick k, s_k its own): the sum over the interval
// telescopes to S^2, the variance of a fully correlated error, whatever the ticks' lengths.
// Within a tick the extra variance is spread along the arc as the wheel noise is: it adds to
// w_L (w_R) in Cov(U) above, which is linear in w_L, w_R. The first tick of an interval carries
// the spread the wheels built up over the detection window before the flag rose (the combiner's
// SideStep::spread), so the disturbance before detection is covered too. Between intervals
// nothing is added: a one-encoder-per-side base never takes this path.

namespace odo {
namespace {

using Mat3 = Eigen::Matrix<double, 3, 3, Eigen::RowMajor>;

// Series/closed-form switch. At |phi| = 1 the closed forms lose at most ~2e-15 (relative) and the
// series below are truncated where the next term is < 1e-18 of the first.
constexpr double kSeriesLimit = 1.0;

// Taylor coefficients in z = phi^2 of the seven basic functions, from term-by-term integration of
// the integrands' series (tools/gen_error_model_series.py prints them).
constexpr double kSinc[] = {1.0,
                            -0.16666666666666666,
                            0.008333333333333333,
                            -0.0001984126984126984,
                            2.7557319223985893e-06,
                            -2.505210838544172e-08,
                            1.6059043836821613e-10,
                            -7.647163731819816e-13,
                            2.8114572543455206e-15,
                            -8.22063524662433e-18,
                            1.9572941063391263e-20};
// h = (1 - cos phi)/phi^2
constexpr double kH[] = {0.5,
                         -0.041666666666666664,
                         0.001388888888888889,
                         -2.48015873015873e-05,
                         2.755731922398589e-07,
                         -2.08767569878681e-09,
                         1.1470745597729725e-11,
                         -4.779477332387385e-14,
                         1.5619206968586225e-16,
                         -4.110317623312165e-19};
// g1 = I_ss / phi^2
constexpr double kG1[] = {0.3333333333333333,      -0.06666666666666667,   0.006349206349206349,
                          -0.0003527336860670194,  1.282667949334616e-05,  -3.2888921777810664e-07,
                          6.264556529106794e-09,   -9.212583131039402e-11, 1.0774951030455441e-12,
                          -1.0261858124243278e-14, 8.11214080967848e-17,   -5.408093873118987e-19,
                          3.081534970438169e-21};
// g2 = J_y / phi
constexpr double kG2[] = {0.3333333333333333,      -0.03333333333333333,   0.0011904761904761906,
                          -2.2045855379188714e-05, 2.505210838544172e-07,  -1.9270852604185937e-09,
                          1.0706029224547743e-11,  -4.498331606952833e-14, 1.4797143443923793e-16,
                          -3.9145882126782523e-19, 8.509974375387505e-22};
// g3 = J_xx
constexpr double kG3[] = {0.3333333333333333,     -0.15,
                          0.025793650793650792,   -0.0021219135802469135,
                          0.00010266354016354016, -3.289213358657803e-06,
                          7.517620778202789e-08,  -1.289767261260025e-09,
                          1.72399380899992e-11,   -1.8471348538226112e-13,
                          1.6224282392990994e-15, -1.1897806649800776e-17,
                          7.395683947418985e-20};
// g4 = J_yy / phi^2
constexpr double kG4[] = {0.13333333333333333,     -0.025396825396825397,   0.0021164021164021165,
                          -0.00010261343594676929, 3.2888921777810667e-06,  -7.517467834928152e-08,
                          1.2897616383455163e-09,  -1.7239921648728706e-11, 1.84713446236379e-13,
                          -1.622428161935696e-15,  1.1897806520861771e-17,  -7.395683929051606e-20};
// g5 = J_xy / phi
constexpr double kG5[] = {0.20833333333333334,    -0.06805555555555555,    0.007961309523809523,
                          -0.000494102733686067,  1.9242106915718025e-05,  -5.168373843969083e-07,
                          1.0179952154571863e-08, -1.5354320837605974e-10, 1.8317420862091875e-12,
                          -1.772502855882662e-14, 1.4196246578111098e-16,  -9.568166108006477e-19,
                          5.502741021919477e-21};

// Shorter series for the small angles of ordinary ticks. Below |phi| = kShortSeriesLimit (0.05 rad
// is 5 rad/s at 100 Hz) the first kShortTerms coefficients suffice: the largest omitted term,
// c_6 z^6 of g3, is 2e-23 of c_0. Below kShortestSeriesLimit (15 rad/s at 1 kHz, 1.5 rad/s at
// 100 Hz) kShortestTerms do: the largest omitted term, c_4 z^4 of g3, is below 8e-19 of c_0
// (2^-60, under half an ulp), so the three tiers agree to the last bit or one ulp.
constexpr double kShortSeriesLimit = 0.05;
constexpr std::size_t kShortTerms = 6;
constexpr double kShortestSeriesLimit = 0.015;
constexpr std::size_t kShortestTerms = 4;
// Below kTinySeriesLimit (2 rad/s at 1 kHz, 0.2 rad/s at 100 Hz: most ticks of a base at 1 kHz)
// kTinyTerms do: the largest omitted term, c_3 z^3 of g3 (|c_3 / c_0| = 6.4e-3, z^3 <= 6.4e-17),
// is below 4.1e-19 of c_0 (2^-61), the next, c_4 z^4, below 8e-26; of the other six functions g5
// omits the most, 1.5e-19. So this tier too agrees with the others to the last bit or one ulp.
constexpr double kTinySeriesLimit = 0.002;
constexpr std::size_t kTinyTerms = 3;

// horner: the polynomial of the first M coefficients of c at z (M = 0: all of them).
template <std::size_t M, std::size_t N>
inline double horner(const double (&c)[N], double z) noexcept {
  constexpr std::size_t kM = M == 0 ? N : M;
  static_assert(kM <= N);
  double r = c[kM - 1];
  for (std::size_t i = kM - 1; i-- > 0;) r = r * z + c[i];
  return r;
}

// Pair: two doubles that one SSE2 (or NEON) instruction processes at once. Every operation
// acts on each lane exactly as the scalar operation would, rounding included, so evaluating two
// series side by side gives the same bits as evaluating them one after the other.
using Pair = double __attribute__((vector_size(16)));

// horner_pair: horner<M> of c0 and of c1 (M > 0) at z, in the lanes of one pair.
template <std::size_t M, std::size_t N0, std::size_t N1>
inline Pair horner_pair(const double (&c0)[N0], const double (&c1)[N1], Pair z) noexcept {
  static_assert(M > 0 && M <= N0 && M <= N1);
  Pair r = {c0[M - 1], c1[M - 1]};
  for (std::size_t i = M - 1; i-- > 0;) r = r * z + Pair{c0[i], c1[i]};
  return r;
}

// The seven basic functions of the arc's swept angle.
struct BasicFunctions {
  double sinc, h, g1, g2, g3, g4, g5;
};

// series: the basic functions at z = phi^2 from the first M Taylor coefficients (0: all). A
// truncated series evaluates six of them two at a time (the full ones differ in length).
template <std::size_t M>
inline BasicFunctions series(double z) noexcept {
  if constexpr (M == 0) {
    return {horner<M>(kSinc, z), horner<M>(kH, z),  horner<M>(kG1, z), horner<M>(kG2, z),
            horner<M>(kG3, z),   horner<M>(kG4, z), horner<M>(kG5, z)};
  } else {
    const Pair zz = {z, z};
    const Pair sh = horner_pair<M>(kSinc, kH, zz);
    const Pair g12 = horner_pair<M>(kG1, kG2, zz);
    const Pair g34 = horner_pair<M>(kG3, kG4, zz);
    return {sh[0], sh[1], g12[0], g12[1], g34[0], g34[1], horner<M>(kG5, z)};
  }
}

// closed_form: the basic functions from sin and cos of phi (for |phi| >= kSeriesLimit).
inline BasicFunctions closed_form(double phi) noexcept {
  const double s = std::sin(phi), c = std::cos(phi);
  const double inv = 1.0 / phi, inv2 = inv * inv;
  const double i_ss = 0.5 * (phi - s * c) * inv;
  BasicFunctions f;
  f.sinc = s * inv;
  f.h = (1.0 - c) * inv2;
  f.g1 = i_ss * inv2;
  f.g2 = (s - phi * c) * inv2 * inv;
  f.g3 = (s * s - 2.0 * s * (1.0 - c) * inv + i_ss) * inv2;
  f.g4 = (0.5 + c * c - 1.5 * s * c * inv) * inv2 * inv2;
  f.g5 = (0.5 * s * s * inv - s * c + c * (1.0 - c) * inv) * inv2 * inv;
  return f;
}

}  // namespace

std::optional<FieldRange> error_model_range(const ErrorModelParams& k) {
  for (const auto& [field, v] : {std::pair{"k_left", k.k_left}, std::pair{"k_right", k.k_right}}) {
    if (!(std::isfinite(v) && v >= 0.0 && v <= kErrorModelKMax))
      return FieldRange{field, v, 0.0, kErrorModelKMax, "m^(1/2)"};
  }
  if (k.covariance_ticks < 1 || k.covariance_ticks > kCovarianceTicksMax)
    return integer_range("covariance_ticks", k.covariance_ticks, 1, kCovarianceTicksMax);
  return std::nullopt;
}

Status check_error_model(const ErrorModelParams& k) {
  if (auto r = error_model_range(k)) return range_error(std::move(*r));
  return Ok{};
}

namespace {

// wide_basic_functions: the tiers beyond the shortest series (|phi| >= kShortestSeriesLimit, a
// turn faster than 15 rad/s at 1 kHz).
inline BasicFunctions wide_basic_functions(double phi, double z) noexcept {
  const double abs_phi = std::fabs(phi);
  return abs_phi < kShortSeriesLimit ? series<kShortTerms>(z)
         : abs_phi < kSeriesLimit    ? series<0>(z)
                                     : closed_form(phi);
}

// narrow_basic_functions: the two tiers below kShortestSeriesLimit. The tiny one is the ordinary
// tick's ([[likely]]: its series fall through to the step instead of jumping there and back).
inline BasicFunctions narrow_basic_functions(double phi, double z) noexcept {
  if (std::fabs(phi) < kTinySeriesLimit) [[likely]]
    return series<kTinyTerms>(z);
  return series<kShortestTerms>(z);
}

// arc_terms_of: the fourteen terms from the basic functions f of phi (z = phi^2); inlined into
// its callers on the tick's path (a call returns the terms through memory; inline they stay in
// registers).
[[gnu::always_inline]] inline ArcTerms arc_terms_of(double phi, double z,
                                                    const BasicFunctions& f) noexcept {
  const double sinc = f.sinc, h = f.h;
  ArcTerms t;
  t.i_c = sinc;
  t.i_s = phi * h;
  t.i_ss = z * f.g1;
  t.i_cc = 1.0 - t.i_ss;
  t.i_cs = 0.5 * phi * sinc * sinc;
  t.j_x = sinc - h;
  t.j_y = phi * f.g2;
  t.j_xx = f.g3;
  t.j_yy = z * f.g4;
  t.j_xy = phi * f.g5;
  t.j_cx = 0.5 * sinc * sinc;
  t.j_cy = phi * f.g1;
  t.j_sy = 0.5 * t.i_s * t.i_s;
  t.j_sx = t.i_c * t.i_s - t.j_cy;
  return t;
}

}  // namespace

ArcTerms arc_terms(double phi) noexcept {
  const double z = phi * phi;
  return arc_terms_of(phi, z,
                      std::fabs(phi) < kShortestSeriesLimit ? narrow_basic_functions(phi, z)
                                                            : wide_basic_functions(phi, z));
}

namespace {

// input_covariance_w: Cov(U) in the arc's start frame from the wheels' noise intensities w_l,
// w_r [m^2] (Chong-Kleeman's k^2 |d|, plus a slip's extra variance).
inline Mat3 input_covariance_w(double w_l, double w_r, double d_left, double d_right, double inv_b,
                               const ArcTerms& t) noexcept {
  const double wp = w_l + w_r, wm = w_l - w_r;
  // a = D / b through the reciprocal the caller keeps (a division is ~570 instructions on a
  // Cortex-M4; the product differs from D / b by at most an ulp).
  const double a = 0.5 * (d_left + d_right) * inv_b;
  Mat3 q;
  q(0, 0) = wp * (0.25 * t.i_cc + a * a * t.j_yy) + wm * a * t.j_cy;
  q(1, 1) = wp * (0.25 * t.i_ss + a * a * t.j_xx) - wm * a * t.j_sx;
  q(0, 1) = q(1, 0) = wp * (0.25 * t.i_cs - a * a * t.j_xy) + 0.5 * wm * a * (t.j_sy - t.j_cx);
  q(2, 2) = wp * inv_b * inv_b;
  q(0, 2) = q(2, 0) = -(wp * a * t.j_y + 0.5 * wm * t.i_c) * inv_b;
  q(1, 2) = q(2, 1) = (wp * a * t.j_x - 0.5 * wm * t.i_s) * inv_b;
  return q;
}

// local_input_covariance: Cov(U) in the arc's start frame plus the arc's displacement there.
inline Mat3 local_input_covariance(double d_left, double d_right, double inv_b,
                                   const ErrorModelParams& k, const ArcTerms& t) noexcept {
  // Not as a pair (-2 instructions on x86-64): where the compiler contracts a multiply and an
  // add into one fused operation (aarch64), w_l + w_r and w_l - w_r become fma(k_L^2, |d_L|, ..)
  // from scalars but not from a pair's lanes, which changes the bits there.
  const double w_l = k.k_left * k.k_left * std::fabs(d_left);
  const double w_r = k.k_right * k.k_right * std::fabs(d_right);
  return input_covariance_w(w_l, w_r, d_left, d_right, inv_b, t);
}

}  // namespace

namespace {

// all_finite: whether none of the five values is infinite or NaN, in one test instead of five:
// x - x is +0 for a finite x and NaN otherwise, a sum with a NaN term is NaN and a sum of +0
// terms is +0, so the sum equals 0 exactly when every value is finite, in any order of its
// terms (four of them taken in pairs here). (Without -ffinite-math-only the compiler may not
// fold x - x to 0.)
inline bool all_finite(double v0, double v1, double v2, double v3, double v4) noexcept {
  const Pair p = (Pair{v0, v1} - Pair{v0, v1}) + (Pair{v3, v4} - Pair{v3, v4});
  return p[0] + p[1] + (v2 - v2) == 0.0;
}

// propagate_local_impl: cov <- F cov F^T + R Q R^T for a step with displacement (lx, ly) and
// input covariance Q (its six distinct entries) in the frame of its start heading (s0, c0).
inline void propagate_local_impl(Cov3& cov, double s0, double c0, double lx, double ly, double q00,
                                 double q01, double q02, double q11, double q12,
                                 double q22) noexcept {
  const double dx = c0 * lx - s0 * ly, dy = s0 * lx + c0 * ly;
  // Written out on the six distinct entries (both terms are symmetric by construction, so the
  // result stays exactly symmetric). F is the identity except F(0,2) = -dy, F(1,2) = dx (Eq. 16:
  // the start heading moves x by -dy and y by +dx); R is the rotation by theta0 about z.
  const double p00 = cov[0], p01 = cov[1], p02 = cov[2], p11 = cov[4], p12 = cov[5], p22 = cov[8];
  const double fa = -dy, fc = dx;
  const double cc = c0 * c0, ss = s0 * s0, cs = c0 * s0;
  const double n00 = p00 + fa * (2.0 * p02 + fa * p22) + cc * q00 - 2.0 * cs * q01 + ss * q11;
  const double n11 = p11 + fc * (2.0 * p12 + fc * p22) + ss * q00 + 2.0 * cs * q01 + cc * q11;
  const double n01 = p01 + fa * p12 + fc * p02 + fa * fc * p22 + cs * (q00 - q11) + (cc - ss) * q01;
  const double n02 = p02 + fa * p22 + c0 * q02 - s0 * q12;
  const double n12 = p12 + fc * p22 + s0 * q02 + c0 * q12;
  const double n22 = p22 + q22;
  cov = {n00, n01, n02, n01, n11, n12, n02, n12, n22};
}

// propagate_arc_terms: propagate_arc once the arc's terms t are known.
[[gnu::always_inline]] inline void propagate_arc_terms(Cov3& cov, double sin_theta0,
                                                       double cos_theta0, double d_left,
                                                       double d_right, double inv_b,
                                                       const ErrorModelParams& k,
                                                       const ArcTerms& t) noexcept {
  const Mat3 q = local_input_covariance(d_left, d_right, inv_b, k, t);
  // Displacement of the arc: D (I_c, I_s) in the start frame.
  const double d = 0.5 * (d_left + d_right);
  propagate_local_impl(cov, sin_theta0, cos_theta0, d * t.i_c, d * t.i_s, q(0, 0), q(0, 1), q(0, 2),
                       q(1, 1), q(1, 2), q(2, 2));
}

// propagate_arc_wide: propagate_arc for the tiers beyond the shortest series (|phi| >=
// kShortestSeriesLimit; z = phi^2): out of line, so that the ordinary tick's copy needs no stack
// frame (values live across a call would go to the stack).
[[gnu::noinline]] void propagate_arc_wide(Cov3& cov, double sin_theta0, double cos_theta0,
                                          double d_left, double d_right, double inv_b,
                                          const ErrorModelParams& k, double phi,
                                          double z) noexcept {
  propagate_arc_terms(cov, sin_theta0, cos_theta0, d_left, d_right, inv_b, k,
                      arc_terms_of(phi, z, wide_basic_functions(phi, z)));
}

}  // namespace

Cov2 twist_covariance(const TickMotion& m, const ErrorModelParams& k) noexcept {
  // v = (dL + dR) / (2 dt) and, from the wheels, omega = (dR - dL) / (b dt), with independent
  // wheel variances wL = kL^2 |dL|, wR = kR^2 |dR|: var v = (wL + wR) / (4 dt^2),
  // var omega = (wL + wR) / (b^2 dt^2), cov(v, omega) = (wR - wL) / (2 b dt^2). On a gyro tick
  // omega = dtheta_gyro / dt: var omega = var_heading / dt^2, and the gyro's noise is
  // independent of the wheels', so the cross term is 0.
  if (!(m.dt > 0.0) || !(m.wheelbase > 0.0)) return Cov2{};
  const double wl = k.k_left * k.k_left * std::fabs(m.d_left);
  const double wr = k.k_right * k.k_right * std::fabs(m.d_right);
  const double dt2 = m.dt * m.dt, b = m.wheelbase;
  if (m.gyro_heading) return Cov2{(wl + wr) / (4.0 * dt2), 0.0, 0.0, m.gyro_var_heading / dt2};
  const double cross = (wr - wl) / (2.0 * b * dt2);
  return Cov2{(wl + wr) / (4.0 * dt2), cross, cross, (wl + wr) / (b * b * dt2)};
}

Cov3 arc_input_covariance(double d_left, double d_right, double b,
                          const ErrorModelParams& k) noexcept {
  Cov3 out{};
  if (!(std::isfinite(d_left) && std::isfinite(d_right) && b > 0.0 && std::isfinite(b))) {
    return out;
  }
  const ArcTerms t = arc_terms((d_right - d_left) / b);
  Eigen::Map<Mat3>(out.data()) = local_input_covariance(d_left, d_right, 1.0 / b, k, t);
  return out;
}

void propagate_arc(Cov3& cov, double theta0, double d_left, double d_right, double b,
                   const ErrorModelParams& k) noexcept {
  if (!std::isfinite(theta0)) return;
  propagate_arc(cov, std::sin(theta0), std::cos(theta0), d_left, d_right, b, k);
}

void propagate_arc(Cov3& cov, double sin_theta0, double cos_theta0, double d_left, double d_right,
                   double b, const ErrorModelParams& k) noexcept {
  propagate_arc_known(cov, sin_theta0, cos_theta0, d_left, d_right, b, 1.0 / b,
                      (d_right - d_left) / b, k);
}

void propagate_arc_known(Cov3& cov, double sin_theta0, double cos_theta0, double d_left,
                         double d_right, double b, double inv_b, double phi,
                         const ErrorModelParams& k) noexcept {
  // A non-finite travel or wheelbase would poison the covariance for good; such a tick (which the
  // loop never produces) adds nothing.
  if (!(all_finite(d_left, d_right, b, sin_theta0, cos_theta0) && b > 0.0)) return;
  const double z = phi * phi;
  if (std::fabs(phi) >= kShortestSeriesLimit) {
    propagate_arc_wide(cov, sin_theta0, cos_theta0, d_left, d_right, inv_b, k, phi, z);
    return;
  }
  propagate_arc_terms(cov, sin_theta0, cos_theta0, d_left, d_right, inv_b, k,
                      arc_terms_of(phi, z, narrow_basic_functions(phi, z)));
}

void propagate_arc_slip(Cov3& cov, double sin_theta0, double cos_theta0, double d_left,
                        double d_right, double b, const ErrorModelParams& k, double var_left,
                        double var_right) noexcept {
  const bool finite =
      all_finite(d_left, d_right, b, sin_theta0, cos_theta0) && std::isfinite(var_left + var_right);
  if (!(finite && b > 0.0)) return;  // a non-finite step would poison the covariance for good
  const double inv_b = 1.0 / b;
  const ArcTerms t = arc_terms((d_right - d_left) / b);
  const double w_l = k.k_left * k.k_left * std::fabs(d_left) + var_left;
  const double w_r = k.k_right * k.k_right * std::fabs(d_right) + var_right;
  const Mat3 q = input_covariance_w(w_l, w_r, d_left, d_right, inv_b, t);
  const double d = 0.5 * (d_left + d_right);
  propagate_local_impl(cov, sin_theta0, cos_theta0, d * t.i_c, d * t.i_s, q(0, 0), q(0, 1), q(0, 2),
                       q(1, 1), q(1, 2), q(2, 2));
}

void PoseCovariance::merge(double sin_theta0, double cos_theta0, double d_left, double d_right,
                           double b, double phi) noexcept {
  // A wheel's variance grows with |d|: summed travels of one sign keep sum |d_i| = |sum d_i|, a
  // reversal within a group would not, so a reversing wheel (or a new wheelbase) closes it.
  Group& g = group_;
  if (g.ticks > 0 && (d_left * g.d_left < 0.0 || d_right * g.d_right < 0.0 || b != g.b)) flush();
  if (g.ticks == 0) {
    g.sin0 = sin_theta0;
    g.cos0 = cos_theta0;
    g.b = b;
  }
  g.d_left += d_left;
  g.d_right += d_right;
  g.phi += phi;  // the group's heading change as the pose integrated it
  if (++g.ticks >= k_.covariance_ticks) flush();
}

void PoseCovariance::flush() noexcept {
  if (group_.ticks == 0) return;
  const Group g = group_;
  group_ = {};
  // One arc from the group's start heading with its summed travels: for ticks on one
  // constant-curvature arc the closed form gives what the ticks one by one give.
  propagate_known(g.sin0, g.cos0, g.d_left, g.d_right, g.b, g.phi);
}

void PoseCovariance::shift_point(double sin_theta, double cos_theta, double e) noexcept {
  // A point P e ahead of the centre C on the body's x axis: P = C + e (cos theta, sin theta), so
  // d P / d (C, theta) = [1 0 -e sin; 0 1 e cos; 0 0 1]: propagate_local's F of a displacement
  // (e, 0) in the frame of theta, with no input noise. Skid steer (Mandow et al. 2007): with
  // the instantaneous centre of rotation x_icr ahead of C, the body's velocity at P = C + x_icr
  // (cos, sin) is (v, -x_icr omega) + omega x (x_icr, 0) = (v, 0): P moves exactly as the centre
  // of a plain differential drive with the same wheel travels and heading, so the wheel noise
  // reaches (P, theta) through the plain arc's Cov(U) (above) and the skid base's covariance is
  // the plain one conjugated by this shift at the tick's start (e = x_icr) and end (e = -x_icr)
  // headings: no further integrals. Merged ticks are propagated first, from their own start.
  flush();
  propagate_local_impl(cov_, sin_theta, cos_theta, e, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
}

void propagate_local(Cov3& cov, double sin_theta0, double cos_theta0, double lx, double ly,
                     const Cov3& q) noexcept {
  propagate_local_impl(cov, sin_theta0, cos_theta0, lx, ly, q[0], q[1], q[2], q[4], q[5], q[8]);
}

}  // namespace odo
