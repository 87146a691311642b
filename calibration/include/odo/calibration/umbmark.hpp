// UMBmark (Borenstein & Feng, UM-MEAM-94-22; Chong & Kleeman Sec. 3): return errors of the
// bi-directional square path, their centres of gravity, E_max,syst, the Type A / Type B errors
// alpha and beta, the correction factors c_L, c_R and the effective wheelbase b_new, their
// composition over passes, the 3 x SEM rule and the extended-UMBmark orientation figure.
// Pure math: inputs as arguments, no I/O. SI units: metres, radians.
//
// Sign convention (the report's Sec. 6.1, checked on the simulator): the start frame has x along
// the first leg and y to the left; cw squares turn right (y < 0), ccw squares turn left.
// alpha > 0: the robot turns LESS than 90 deg at every corner, in both directions (Type A);
// beta > 0: every straight leg curves to the LEFT, i.e. the right wheel travels further per
// count than the odometry believes (Type B). Then (Eq. 6.19/6.20 and the y analogues)
//   x_cw = -2L(alpha + beta),  x_ccw = -2L(alpha - beta),
//   y_cw = -2L(alpha + beta),  y_ccw = +2L(alpha - beta).
#pragma once

#include <optional>
#include <span>
#include <string>
#include <vector>

#include "odo/hal/choice.hpp"
#include "odo/hal/result.hpp"

namespace odo::calib {

enum class Direction { kCw, kCcw };
// How runs' directions are spelt (the runs CSV, messages, odomctl's prompts).
inline constexpr Choice<Direction> kDirections[] = {{Direction::kCw, "cw"},
                                                    {Direction::kCcw, "ccw"}};

// One UMBmark run: the return error absolute minus calculated (Eq. 3.1) in the start frame.
struct UmbmarkRun {
  Direction direction = Direction::kCw;
  double ex = 0.0;               // [m]
  double ey = 0.0;               // [m]
  std::optional<double> etheta;  // [rad], needed for the extended UMBmark figure only
  bool bumps = false;            // an extended-UMBmark run (ten bumps on the first leg)
};

// Centre of gravity of the plain runs of one direction (Eq. 3.2, 3.3).
struct CentreOfGravity {
  int n = 0;       // number of runs averaged
  double x = 0.0;  // x_cg [m]
  double y = 0.0;  // y_cg [m]
  double r = 0.0;  // r_cg = sqrt(x_cg^2 + y_cg^2) [m]
};

// Type A and Type B orientation errors per corner / per leg [rad] (Eq. 6.22, 6.26).
struct TypeAB {
  double alpha_x = 0.0, alpha_y = 0.0, alpha = 0.0;  // from x, from y, average
  double beta_x = 0.0, beta_y = 0.0, beta = 0.0;
};

// Which formula turns alpha into the wheelbase factor: the report's Eq. 6.29
// E_b = (pi/2) / ((pi/2) - alpha) or Chong & Kleeman's Eq. 9 c_b = pi / (pi - alpha).
// The simulator decides for 6.29 (README, "Eq. 6.29 against Chong & Kleeman Eq. 9"): alpha is
// the error of a 90 deg corner, so 90/(90 - alpha) follows from Eq. 6.27; Eq. 9 corrects half of
// it. On the simulated LabMate (b 337 mm, believed 340 mm, no noise) one pass with Eq. 6.29 gives
// b = 337.06 mm and E_max,syst 353.96 -> 4.61 mm (76.8-fold); Eq. 9 gives b = 338.52 mm and
// 353.96 -> 81.47 mm (4.3-fold), 40.17 mm after a second pass.
enum class WheelbaseFormula { kUmbmark629, kChongKleeman9 };
// Their spellings (odomctl umbmark simulate --eb-form).
inline constexpr Choice<WheelbaseFormula> kWheelbaseFormulas[] = {
    {WheelbaseFormula::kUmbmark629, "umbmark"}, {WheelbaseFormula::kChongKleeman9, "chong"}};

// Calibration factors of a robot: c_L, c_R (Eq. 6.35) and the wheelbase b [m] it uses.
struct Factors {
  double c_l = 1.0;
  double c_r = 1.0;
  double wheelbase = 0.0;  // [m]
};

// The largest |alpha|, |beta| [rad] the small-angle model of Sec. 6.1 is used for (5.7 deg; a
// LabMate's uncalibrated errors are about 0.02 rad, millimetres typed as metres give radians).
inline constexpr double kMaxAngle = 0.1;
// Fewer runs a direction than this draws a warning (the report uses n = 5).
inline constexpr int kRecommendedRuns = 5;

// centre_of_gravity: Eq. 3.2/3.3 over the runs of `dir` with bumps == false (n = 0: all zero).
CentreOfGravity centre_of_gravity(std::span<const UmbmarkRun> runs, Direction dir);

// e_max_syst: Eq. 3.4, max(r_cg,cw, r_cg,ccw) [m].
double e_max_syst(const CentreOfGravity& cw, const CentreOfGravity& ccw);

// type_ab: alpha and beta [rad] from the centres of gravity for a square of side L [m]
// (Eq. 6.22a/b, 6.26a/b in radians, x and y estimates averaged as in Chong & Kleeman Eq. 6/7).
TypeAB type_ab(const CentreOfGravity& cw, const CentreOfGravity& ccw, double side);

// curvature_radius: Eq. 6.23, R = (L/2) / sin(beta/2) [m] for side L [m]; nullopt for beta = 0
// (a straight leg). Positive R: the leg curves to the left.
std::optional<double> curvature_radius(double beta, double side);

// diameter_ratio: Eq. 6.24, E_d = D_R/D_L = (R + b/2)/(R - b/2) for radius R [m] (nullopt:
// straight, E_d = 1) and wheelbase b [m].
double diameter_ratio(std::optional<double> radius, double wheelbase);

// wheelbase_factor: E_b from alpha [rad]: Eq. 6.29 (pi/2)/((pi/2) - alpha) or C&K Eq. 9.
double wheelbase_factor(double alpha, WheelbaseFormula f = WheelbaseFormula::kUmbmark629);

// PassFactors: what one pass finds: wheel factors c_L, c_R and the wheelbase ratio E_b (a
// ratio, not metres).
struct PassFactors {
  double c_l = 1.0;
  double c_r = 1.0;
  double e_b = 1.0;
};

// wheel_factors: Eq. 6.33/6.34, c_L = 2/(E_d + 1), c_R = 2/(1/E_d + 1); keeps (D_L+D_R)/2; E_b 1.
PassFactors wheel_factors(double e_d);

// compose: the factors after a pass on a robot that already ran with `current`: the pass saw
// the compensated robot as a new robot, so c_L = c_L,cur * c_L,pass, c_R = c_R,cur * c_R,pass and
// b = E_b * b_cur [m].
Factors compose(const Factors& current, const PassFactors& pass);

// return_spread: sigma [m], the pooled standard deviation of the return positions about their
// direction's centre of gravity: sqrt(sum |e_i - cg_dir|^2 / (n_cw + n_ccw - 2)) over the plain
// runs; nullopt with fewer than 3 runs in all.
std::optional<double> return_spread(std::span<const UmbmarkRun> runs, const CentreOfGravity& cw,
                                    const CentreOfGravity& ccw);

// second_pass_recommended: the report's rule of thumb (Sec. 6.3): a second pass is worthwhile
// when E_max,syst [m] of the compensated robot's runs > 3 * SEM [m] of the same runs
// (SEM = sigma / sqrt(n)).
bool second_pass_recommended(double e_max_syst, double sem);

// SetSpread: the 3 x SEM rule applied to one set of runs, all three figures of that set.
struct SetSpread {
  std::optional<double> sigma;  // [m], see return_spread()
  double sem = 0.0;             // sigma / sqrt(min(n_cw, n_ccw)) [m] (0 without sigma)
  // E_max,syst > 3 SEM of this set: a (further) pass computed from these runs is worthwhile.
  // On a verification set this is the report's "second compensation" question. Without sigma
  // (fewer than 3 runs) true: the safe side.
  bool worthwhile = true;
};

// set_spread: sigma [m], SEM [m] and the 3 x SEM verdict of the plain runs of one set whose
// centres of gravity are cw, ccw.
SetSpread set_spread(std::span<const UmbmarkRun> runs, const CentreOfGravity& cw,
                     const CentreOfGravity& ccw);

// eps_theta_nonsys: extended UMBmark (Eq. 3.5/3.6 as reconstructed, see README): the mean of
// |etheta_i - mu_dir| over the bump runs of each direction, summed over the directions that have
// bump runs, where mu_dir is the mean etheta of the plain runs of that direction (the
// systematic bias, Eq. 3.6) [rad]. nullopt without bump runs; an error (naming the direction)
// when a bump run or the plain runs it needs lack etheta.
Result<std::optional<double>> eps_theta_nonsys(std::span<const UmbmarkRun> runs);

struct UmbmarkInput {
  std::vector<UmbmarkRun> runs;
  double side = 4.0;               // L [m]
  Factors current{1.0, 1.0, 0.0};  // factors and wheelbase [m] the robot used during the runs
  WheelbaseFormula formula = WheelbaseFormula::kUmbmark629;
};

struct UmbmarkResult {
  CentreOfGravity cw, ccw;
  double e_max_syst = 0.0;       // [m]
  TypeAB ab;                     // [rad]
  std::optional<double> radius;  // R [m]; nullopt when beta = 0
  double e_d = 1.0;              // Eq. 6.24
  double e_b = 1.0;              // Eq. 6.29 (or C&K Eq. 9)
  PassFactors pass;              // this pass alone: c_L, c_R (Eq. 6.33/6.34) and E_b
  Factors composed;              // what to use from now on: c_l, c_r, b_new [m] (Eq. 6.28)
  SetSpread spread;              // of the input runs: whether a pass on them is worthwhile
  std::optional<double> eps_theta_nonsys;  // [rad]
  std::vector<std::string> warnings;       // e.g. fewer than 5 runs a direction
};

// factor_sigmas: the standard deviations of `r.composed` (c_l, c_r, b_new [m]) from the spread
// of the runs of `in` it was computed from: each direction's centre of gravity is uncertain by
// its SEM (sigma / sqrt(n)) in x and in y, independently; each of these four is moved by its SEM
// (every plain run of the direction shifted), the set computed again, and the changes of the
// factors added in quadrature (first order). nullopt without a spread (fewer than 3 runs) or
// when a moved set does not compute.
std::optional<Factors> factor_sigmas(const UmbmarkInput& in, const UmbmarkResult& r);

// umbmark_compute: the whole UMBmark calculation. Errors (Errc::kInvalidArgument, message names
// the field and the allowed range): side or wheelbase not positive and finite, a current factor
// outside [0.9, 1.1], a non-finite run value, no plain run in a direction, |alpha| or |beta| >
// kMaxAngle (usually mm typed as m), composed factors outside [0.9, 1.1].
Result<UmbmarkResult> umbmark_compute(const UmbmarkInput& in);

}  // namespace odo::calib
