// Internal to calibration/: the exact excursion model with its analytic Jacobian, the residual
// covariance of an excursion, and the evaluation of a chain of accepted fixes.
#pragma once

#include <Eigen/Core>
#include <span>
#include <vector>

#include "odo/calibration/selfcal.hpp"

namespace odo::calib::detail {

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;

// Chi-square 99.9 % quantiles for 2 (x, y) and 3 (x, y, theta) degrees of freedom.
inline constexpr double kGate2 = 13.8155;
inline constexpr double kGate3 = 16.2662;

inline Vec3 to_vec(const Factors& f) {
  return Vec3(f.c_l, f.c_r, f.wheelbase);
}
inline Factors to_factors(const Vec3& p) {
  return Factors{p(0), p(1), p(2)};
}

// The pose at the end of an excursion and its derivatives.
struct Prediction {
  Pose2 end;
  Mat3 d_param = Mat3::Zero();  // d(x, y, theta)_end / d(c_L, c_R, b)
  Mat3 odo_cov = Mat3::Zero();  // Chong-Kleeman covariance of the end pose (world frame)
};

// integrate: the excursion over legs[from .. to) from `start` whose heading has derivative
// dtheta0 with respect to p; odometry covariance only when `with_cov`.
Prediction integrate(const FixTrack& t, int from, int to, const Pose2& start, const Vec3& dtheta0,
                     const Vec3& p, double c_m, const ErrorModelParams* with_cov);

// One excursion between two accepted fixes, evaluated at a parameter vector.
struct Eval {
  int from = 0, to = 0;       // fix indices
  bool usable = false;        // false: start heading unknown
  int dof = 0;                // 2 (x, y) or 3 (x, y, theta)
  Vec3 r = Vec3::Zero();      // fix - prediction (theta wrapped)
  Mat3 j = Mat3::Zero();      // d prediction / d p
  Mat3 s = Mat3::Zero();      // residual covariance (fix, start fix propagated, odometry noise)
  Mat3 g = Mat3::Identity();  // d prediction / d start pose
};

// evaluate_chain: every excursion between consecutive entries of `accepted` (fix indices in
// increasing order), with the start heading chained as the header of selfcal.hpp describes;
// S is computed only when `with_cov` (otherwise left zero).
std::vector<Eval> evaluate_chain(const FixTrack& t, std::span<const int> accepted, const Vec3& p,
                                 const SelfCalConfig& c, bool with_cov);

// chi2: r^T S^-1 r over the first dof rows, with `extra` added to S.
double chi2(const Eval& e, const Mat3& extra = Mat3::Zero());

// weight: S^-1 of the measured rows, zero in the row and column of an unmeasured heading.
Mat3 weight(const Eval& e);

// gate: kGate2 or kGate3 for e.dof.
inline double gate(const Eval& e) {
  return e.dof == 3 ? kGate3 : kGate2;
}

// The result of one fit (selfcal.cpp).
struct FitOut {
  Vec3 initial = Vec3::Zero();  // linear (Antonelli et al.) value
  Vec3 p = Vec3::Zero();        // Gauss-Newton
  Mat3 cov = Mat3::Zero();
  int iterations = 0;
  bool ok = false;       // false: the start value was not plausible
  bool bounded = false;  // a step was shortened to stay in the plausible box
};

// fit_once: linear initial value and Gauss-Newton over the excursions of `acc` admitted by
// `train` (empty: all).
FitOut fit_once(const FixTrack& t, std::span<const int> acc, const SelfCalConfig& c,
                const std::vector<bool>& train);

// check_track: fixes valid (finite, sigmas positive, times increasing), legs.size() ==
// fixes.size() - 1, at least two fixes.
Status check_track(const FixTrack& t);

}  // namespace odo::calib::detail
