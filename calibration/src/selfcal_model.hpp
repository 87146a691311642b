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

// The fitted parameters: N = 3 (c_L, c_R, b), or N = 4 with the ICR offset x_ICR [m] last
// (IcrFit::kFit). Everything below is instantiated for both; N = 3 is the plain fit's code.
template <int N>
using VecP = Eigen::Matrix<double, N, 1>;
template <int N>
using MatP = Eigen::Matrix<double, N, N>;
template <int N>
using JacP = Eigen::Matrix<double, 3, N>;  // d(x, y, theta) / d p

// Chi-square 99.9 % quantiles for 2 (x, y) and 3 (x, y, theta) degrees of freedom.
inline constexpr double kGate2 = 13.8155;
inline constexpr double kGate3 = 16.2662;

// to_vec: the parameter vector of the calibration in use (x_ICR last when N = 4).
template <int N>
VecP<N> to_vec(const Factors& f, double x_icr) {
  VecP<N> p;
  p.template head<3>() = Vec3(f.c_l, f.c_r, f.wheelbase);
  if constexpr (N == 4) p(3) = x_icr;
  return p;
}
template <int N>
VecP<N> in_use(const SelfCalConfig& c) {
  return to_vec<N>(c.in_use, c.x_icr);
}
template <int N>
Factors to_factors(const VecP<N>& p) {
  return Factors{p(0), p(1), p(2)};
}
// x_icr_of: the ICR offset the model uses at p: fitted (N = 4) or the one in use [m].
template <int N>
double x_icr_of(const VecP<N>& p, const SelfCalConfig& c) {
  if constexpr (N == 4) return p(3);
  return c.x_icr;
}

// The pose at the end of an excursion and its derivatives.
template <int N>
struct Prediction {
  Pose2 end;
  JacP<N> d_param = JacP<N>::Zero();  // d(x, y, theta)_end / d p
  Mat3 odo_cov = Mat3::Zero();        // Chong-Kleeman covariance of the end pose (world frame)
};

// integrate: the excursion over legs[from .. to) from `start` whose heading has derivative
// dtheta0 with respect to p, the body turning about the point x_icr [m] ahead of its centre
// (x_icr_of); odometry covariance only when `with_cov`.
template <int N>
Prediction<N> integrate(const FixTrack& t, int from, int to, const Pose2& start,
                        const VecP<N>& dtheta0, const VecP<N>& p, double x_icr, double c_m,
                        const ErrorModelParams* with_cov);

// One excursion between two accepted fixes, evaluated at a parameter vector.
template <int N>
struct Eval {
  int from = 0, to = 0;         // fix indices
  bool usable = false;          // false: start heading unknown
  int dof = 0;                  // 2 (x, y) or 3 (x, y, theta)
  Vec3 r = Vec3::Zero();        // fix - prediction (theta wrapped)
  JacP<N> j = JacP<N>::Zero();  // d prediction / d p
  Mat3 s = Mat3::Zero();        // residual covariance (fix, start fix propagated, odometry noise)
  Mat3 g = Mat3::Identity();    // d prediction / d start pose
};

// evaluate_chain: every excursion between consecutive entries of `accepted` (fix indices in
// increasing order), with the start heading chained as the header of selfcal.hpp describes;
// S is computed only when `with_cov` (otherwise left zero).
template <int N>
std::vector<Eval<N>> evaluate_chain(const FixTrack& t, std::span<const int> accepted,
                                    const VecP<N>& p, const SelfCalConfig& c, bool with_cov);

// chi2: r^T S^-1 r over the first dof rows, with `extra` added to S.
template <int N>
double chi2(const Eval<N>& e, const Mat3& extra = Mat3::Zero());

// gate: kGate2 or kGate3 for e.dof.
template <int N>
double gate(const Eval<N>& e) {
  return e.dof == 3 ? kGate3 : kGate2;
}

// The result of one fit (selfcal.cpp).
template <int N>
struct FitOut {
  VecP<N> initial = VecP<N>::Zero();  // linear (Antonelli et al.) value (x_ICR: the one in use)
  VecP<N> p = VecP<N>::Zero();        // Gauss-Newton
  MatP<N> cov = MatP<N>::Zero();
  int iterations = 0;
  bool ok = false;       // false: the start value was not plausible
  bool bounded = false;  // a step was shortened to stay in the plausible box
};

// fit_once: linear initial value and Gauss-Newton over the excursions of `acc` admitted by
// `train` (empty: all).
template <int N>
FitOut<N> fit_once(const FixTrack& t, std::span<const int> acc, const SelfCalConfig& c,
                   const std::vector<bool>& train);

// check_track: fixes valid (finite, sigmas positive, times increasing), legs.size() ==
// fixes.size() - 1, at least two fixes.
Status check_track(const FixTrack& t);

}  // namespace odo::calib::detail
