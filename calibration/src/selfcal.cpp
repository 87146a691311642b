#include "odo/calibration/selfcal.hpp"

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <string>

#include "odo/odometry/kinematics.hpp"
#include "selfcal_model.hpp"

namespace odo::calib {
namespace {

using detail::Eval;
using detail::Mat3;
using detail::MatP;
using detail::Vec3;
using detail::VecP;
using Vec2 = Eigen::Vector2d;
using Mat2 = Eigen::Matrix2d;

// positive: a value that must be positive and finite, worded by range_message.
Error positive(std::string field, double v, const char* unit = "") {
  return range_error(positive_range(std::move(field), v, unit));
}

Status check_fixes(std::span<const PoseFix> fixes) {
  for (std::size_t i = 0; i < fixes.size(); ++i) {
    const PoseFix& f = fixes[i];
    const std::string n = "fix " + std::to_string(i + 1) + " ";
    if (!(std::isfinite(f.x) && std::isfinite(f.y) && (!f.theta || std::isfinite(*f.theta))))
      return make_error(Errc::kInvalidArgument, n + "x, y, theta must be finite");
    if (!(std::isfinite(f.sigma_xy) && f.sigma_xy > 0.0))
      return positive(n + "sigma_xy", f.sigma_xy, "m");
    if (f.theta && !(std::isfinite(f.sigma_theta) && f.sigma_theta > 0.0))
      return positive(n + "sigma_theta", f.sigma_theta, "rad");
    if (i > 0 && f.t <= fixes[i - 1].t)
      return make_error(Errc::kInvalidArgument, n + "time is not after the previous fix's");
  }
  return Ok{};
}

template <int N>
MatP<N> prior_information(const SelfCalConfig& c) {
  const double sf = c.prior_sigma_factor, sb = c.prior_sigma_wheelbase;
  VecP<N> d;
  d.template head<3>() = Vec3(1.0 / (sf * sf), 1.0 / (sf * sf), 1.0 / (sb * sb));
  if constexpr (N == 4) d(3) = 1.0 / (c.prior_sigma_x_icr * c.prior_sigma_x_icr);
  return d.asDiagonal();
}

// Sums of the counts of an excursion (legs[from .. to)).
Vec2 total_counts(const FixTrack& t, int from, int to) {
  Vec2 n = Vec2::Zero();
  for (int leg = from; leg < to; ++leg)
    for (const LegCounts& s : t.legs[static_cast<std::size_t>(leg)]) n += Vec2(s.n_left, s.n_right);
  return n;
}

// Step 1 of Antonelli et al.: heading change c_m (u_R N_R - u_L N_L) between heading fixes,
// least squares in u = (u_L, u_R) with a prior at the calibration in use.
Vec2 linear_heading(const FixTrack& t, std::span<const int> acc, const SelfCalConfig& c) {
  const double b0 = c.in_use.wheelbase, su = c.prior_sigma_factor / b0;
  const Vec2 u0(c.in_use.c_l / b0, c.in_use.c_r / b0);
  Mat2 h = Mat2::Identity() / (su * su);
  Vec2 g = h * u0;
  for (std::size_t k = 0; k + 1 < acc.size(); ++k) {
    const PoseFix &fs = t.fixes[acc[k]], &fe = t.fixes[acc[k + 1]];
    if (!fs.theta || !fe.theta) continue;
    const Vec2 n = total_counts(t, acc[k], acc[k + 1]);
    const Vec2 a(-c.metres_per_count * n(0), c.metres_per_count * n(1));
    // Whole turns are not visible in a wrapped heading: take them from the in-use prediction.
    const double pred = a.dot(u0);
    const double meas = pred + wrap_angle(*fe.theta - *fs.theta - pred);
    const double w = 1.0 / (fs.sigma_theta * fs.sigma_theta + fe.sigma_theta * fe.sigma_theta);
    h += w * a * a.transpose();
    g += w * meas * a;
  }
  return h.ldlt().solve(g);
}

// Step 2: with u known every segment's heading is known, so the position change is
// c_L a_L + c_R a_R; least squares in (c_L, c_R) with the prior, over heading-fix starts.
Vec2 linear_position(const FixTrack& t, std::span<const int> acc, const SelfCalConfig& c,
                     const Vec2& u) {
  const double sf = c.prior_sigma_factor, c_m = c.metres_per_count;
  Mat2 h = Mat2::Identity() / (sf * sf);
  Vec2 g = h * Vec2(c.in_use.c_l, c.in_use.c_r);
  for (std::size_t k = 0; k + 1 < acc.size(); ++k) {
    const PoseFix &fs = t.fixes[acc[k]], &fe = t.fixes[acc[k + 1]];
    if (!fs.theta) continue;
    double th = *fs.theta;
    Mat2 a = Mat2::Zero();  // columns: c_L, c_R; rows: x, y
    for (int leg = acc[k]; leg < acc[k + 1]; ++leg) {
      for (const LegCounts& s : t.legs[static_cast<std::size_t>(leg)]) {
        const double turn = c_m * (u(1) * s.n_right - u(0) * s.n_left);
        const HalfAngle ha = half_angle(0.5 * turn);
        const Vec2 dir(std::cos(th + 0.5 * turn), std::sin(th + 0.5 * turn));
        a.col(0) += 0.5 * c_m * s.n_left * ha.sinc * dir;
        a.col(1) += 0.5 * c_m * s.n_right * ha.sinc * dir;
        th += turn;
      }
    }
    const double w = 1.0 / (fs.sigma_xy * fs.sigma_xy + fe.sigma_xy * fe.sigma_xy);
    h += w * a.transpose() * a;
    g += w * a.transpose() * Vec2(fe.x - fs.x, fe.y - fs.y);
  }
  return h.ldlt().solve(g);
}

// plausible: p inside the box (factors 0.5 .. 1.5, b within 0.5 .. 2 b0, x_ICR what the
// kinematics accept).
template <int N>
bool plausible(const VecP<N>& p, double b0) {
  bool icr = true;
  if constexpr (N == 4) icr = KinematicLimits::kXIcr.contains(p(3));
  return p.allFinite() && p(0) > 0.5 && p(0) < 1.5 && p(1) > 0.5 && p(1) < 1.5 && p(2) > 0.5 * b0 &&
         p(2) < 2.0 * b0 && icr;
}

// linear_initial: Antonelli et al.'s (c_L, c_R, b) (the plain arcs); x_ICR the value in use.
template <int N>
VecP<N> linear_initial(const FixTrack& t, std::span<const int> acc, const SelfCalConfig& c) {
  const Vec2 u = linear_heading(t, acc, c);
  const Vec2 cf = linear_position(t, acc, c, u);
  // (c_L, c_R) = b (u_L, u_R) in the least-squares sense.
  const VecP<N> p = detail::to_vec<N>({cf(0), cf(1), cf.dot(u) / u.squaredNorm()}, c.x_icr);
  return plausible<N>(p, c.in_use.wheelbase) ? p : detail::in_use<N>(c);
}

// The stacked residual rows of the excursions a fit uses, and their joint covariance: each
// excursion's S on the diagonal, and between consecutive excursions that share a fix the
// covariance its error creates, Cov(r_k, r_k+1) = -Sigma_fix G_k+1^T (it ends r_k and starts
// r_k+1; an unknown heading of the fix is not shared).
struct Joint {
  std::vector<std::size_t> index;  // eval index of each used excursion
  Eigen::LLT<Eigen::MatrixXd> llt;
  int rows = 0;
};

template <int N>
Joint joint_covariance(const FixTrack& t, const std::vector<Eval<N>>& s0,
                       const std::vector<bool>& train) {
  Joint j;
  std::vector<int> offset;
  for (std::size_t k = 0; k < s0.size(); ++k) {
    if (!s0[k].usable || (!train.empty() && !train[k])) continue;
    j.index.push_back(k);
    offset.push_back(j.rows);
    j.rows += s0[k].dof;
  }
  Eigen::MatrixXd sigma = Eigen::MatrixXd::Zero(j.rows, j.rows);
  for (std::size_t i = 0; i < j.index.size(); ++i) {
    const Eval<N>& e = s0[j.index[i]];
    sigma.block(offset[i], offset[i], e.dof, e.dof) = e.s.topLeftCorner(e.dof, e.dof);
    if (i + 1 == j.index.size() || s0[j.index[i + 1]].from != e.to) continue;
    const Eval<N>& n = s0[j.index[i + 1]];
    const PoseFix& f = t.fixes[static_cast<std::size_t>(e.to)];
    const double v = f.sigma_xy * f.sigma_xy;
    const Vec3 d(v, v, f.theta ? f.sigma_theta * f.sigma_theta : 0.0);
    const Mat3 off = -(d.asDiagonal() * n.g.transpose());
    sigma.block(offset[i], offset[i + 1], e.dof, n.dof) = off.topLeftCorner(e.dof, n.dof);
    sigma.block(offset[i + 1], offset[i], n.dof, e.dof) =
        off.topLeftCorner(e.dof, n.dof).transpose();
  }
  j.llt.compute(sigma);
  return j;
}

// Outer passes of gauss_newton: the joint covariance is re-evaluated at the estimate of the
// pass before. Frozen at the start value it weighted a wrong geometry: with the scale free the
// linear start was 3-12 % off and the converged estimates landed 4-6 sigma from the truth
// (issue 34); from the values in use three passes were enough (errors 0.94-1.09 x the exact
// model's, 12 seeds).
constexpr int kWeightPasses = 3;

// gn_pass: Gauss-Newton iterations from p with the joint covariance `jc`; f.p, f.cov (the
// inverse of the posterior information at the last linearisation) and the counts in f.
template <int N>
void gn_pass(const FixTrack& t, std::span<const int> acc, const SelfCalConfig& c, const Joint& jc,
             detail::FitOut<N>& f) {
  const MatP<N> p_inf = prior_information<N>(c);
  const VecP<N> prior = detail::in_use<N>(c);
  Eigen::MatrixXd jac(jc.rows, N);
  Eigen::VectorXd res(jc.rows);
  MatP<N> h = p_inf;
  for (int it = 1; it <= c.max_iterations; ++it) {
    ++f.iterations;
    const std::vector<Eval<N>> ev = detail::evaluate_chain<N>(t, acc, f.p, c, false);
    int row = 0;
    for (std::size_t k : jc.index) {
      jac.middleRows(row, ev[k].dof) = ev[k].j.topRows(ev[k].dof);
      res.segment(row, ev[k].dof) = ev[k].r.head(ev[k].dof);
      row += ev[k].dof;
    }
    // Whitened: A = L^-1 J, b = L^-1 r with Sigma = L L^T.
    const Eigen::MatrixXd a = jc.llt.matrixL().solve(jac);
    const Eigen::VectorXd b = jc.llt.matrixL().solve(res);
    h = p_inf + a.transpose() * a;
    VecP<N> step = h.ldlt().solve(p_inf * (prior - f.p) + a.transpose() * b);
    // Outliers not yet rejected can pull the estimate far out: shorten the step to stay in the
    // plausible box and stop there; the rejection that follows needs an estimate to score the
    // fixes with, not a failure.
    int halve = 0;
    for (; halve < 40 && !plausible<N>(f.p + step, c.in_use.wheelbase); ++halve) step *= 0.5;
    if (!plausible<N>(f.p + step, c.in_use.wheelbase)) break;
    f.bounded = f.bounded || halve > 0;
    f.p += step;
    if (step.cwiseAbs().maxCoeff() < 1e-13) break;
  }
  f.cov = h.inverse();
}

// gauss_newton: exact-model refinement over the excursions of `acc` that `train` admits
// (train empty: all) from p, with the prior N(in use, sigma_prior); the joint covariance is
// re-evaluated at the estimate between passes.
template <int N>
detail::FitOut<N> gauss_newton(const FixTrack& t, std::span<const int> acc, const SelfCalConfig& c,
                               const VecP<N>& p, const std::vector<bool>& train) {
  detail::FitOut<N> f;
  f.p = p;
  for (int pass = 0; pass < kWeightPasses; ++pass)
    gn_pass<N>(t, acc, c,
               joint_covariance<N>(t, detail::evaluate_chain<N>(t, acc, f.p, c, true), train), f);
  f.ok = true;
  return f;
}

}  // namespace

namespace detail {

template <int N>
FitOut<N> fit_once(const FixTrack& t, std::span<const int> acc, const SelfCalConfig& c,
                   const std::vector<bool>& train) {
  // Start from the values in use (the prior's mean), not from the linear estimate: that one
  // was 3-12 % off on open drives and Gauss-Newton stalled at the box's edge from there.
  FitOut<N> f = gauss_newton<N>(t, acc, c, in_use<N>(c), train);
  f.initial = linear_initial<N>(t, acc, c);
  return f;
}

template FitOut<3> fit_once<3>(const FixTrack&, std::span<const int>, const SelfCalConfig&,
                               const std::vector<bool>&);
template FitOut<4> fit_once<4>(const FixTrack&, std::span<const int>, const SelfCalConfig&,
                               const std::vector<bool>&);

Status check_track(const FixTrack& t) {
  if (t.fixes.size() < 2)
    return make_error(Errc::kInvalidArgument,
                      "at least two fixes are needed, got " + std::to_string(t.fixes.size()));
  if (t.legs.size() + 1 != t.fixes.size())
    return make_error(Errc::kInvalidArgument, "a track needs one leg between every two fixes");
  return check_fixes(t.fixes);
}

}  // namespace detail

const char* verdict_name(Verdict v) noexcept {
  // The table's names are string literals: their data() is NUL-terminated.
  return choice_name(kVerdictNames, v).data();
}

Status check_selfcal_config(const SelfCalConfig& c) {
  if (!(std::isfinite(c.metres_per_count) && c.metres_per_count > 0.0))
    return positive("metres_per_count", c.metres_per_count, "m");
  const Limit factor = KinematicLimits::kFactor;  // what the loop's kinematics accept
  for (auto [f, v] : {std::pair{"c_l", c.in_use.c_l}, {"c_r", c.in_use.c_r}})
    if (!factor.contains(v)) return range_error({f, v, factor.lo, factor.hi});
  if (!(std::isfinite(c.in_use.wheelbase) && c.in_use.wheelbase > 0.0))
    return positive("wheelbase", c.in_use.wheelbase, "m");
  for (auto [f, v] : {std::pair{"prior_sigma_factor", c.prior_sigma_factor},
                      {"prior_sigma_wheelbase", c.prior_sigma_wheelbase},
                      {"max_sigma_factor", c.max_sigma_factor},
                      {"max_sigma_wheelbase", c.max_sigma_wheelbase},
                      {"prior_sigma_x_icr", c.prior_sigma_x_icr},
                      {"max_sigma_x_icr", c.max_sigma_x_icr}}) {
    if (!(std::isfinite(v) && v > 0.0)) return positive(f, v);
  }
  if (const Limit x = KinematicLimits::kXIcr; !x.contains(c.x_icr))
    return range_error({"x_icr", c.x_icr, x.lo, x.hi, "m"});
  if (!(c.min_improvement >= 0.0 && c.min_improvement <= 0.9))
    return range_error({"min_improvement", c.min_improvement, 0.0, 0.9});
  if (auto s = check_error_model(c.odometry_noise); !s) return s;
  if (c.max_iterations < 1 || c.max_iterations > 100)
    return range_error(integer_range("max_iterations", c.max_iterations, 1, 100));
  if (c.hold_out_every < 0 || c.hold_out_every == 1 || c.hold_out_every > 1000) {
    FieldRange r = integer_range("hold_out_every", c.hold_out_every, 2, 1000);
    r.note = "(or 0: no hold-out)";
    return range_error(std::move(r));
  }
  return Ok{};
}

Pose2 predict_excursion(const Pose2& start, std::span<const LegCounts> legs, const Factors& f,
                        double metres_per_count, double x_icr) {
  Pose2 q = start;
  for (const LegCounts& s : legs)
    q = arc_step_icr(q, f.c_l * metres_per_count * s.n_left, f.c_r * metres_per_count * s.n_right,
                     f.wheelbase, x_icr);
  return q;
}

Result<FixTrack> build_track(std::span<const CountSegment> segments,
                             std::span<const PoseFix> fixes) {
  FixTrack t;
  t.fixes.assign(fixes.begin(), fixes.end());
  if (fixes.size() < 2) return t;
  t.legs.resize(fixes.size() - 1);
  for (std::size_t i = 1; i < fixes.size(); ++i)
    if (fixes[i].t <= fixes[i - 1].t)
      return make_error(Errc::kInvalidArgument,
                        "fix " + std::to_string(i + 1) + ": time is not after the previous fix's");
  TimeNs prev_end = segments.empty() ? 0 : segments.front().t_start;
  for (std::size_t k = 0; k < segments.size(); ++k) {
    const CountSegment& s = segments[k];
    if (s.t_end < s.t_start || s.t_start < prev_end)
      return make_error(Errc::kInvalidArgument,
                        "segment " + std::to_string(k + 1) + " is out of time order");
    prev_end = s.t_end;
    // First fix interval that can overlap (t_start, t_end]: the last fix at or before t_start.
    auto it = std::upper_bound(fixes.begin(), fixes.end(), s.t_start,
                               [](TimeNs v, const PoseFix& f) { return v < f.t; });
    std::size_t i = it == fixes.begin() ? 0 : static_cast<std::size_t>(it - fixes.begin()) - 1;
    const double dur = static_cast<double>(s.t_end - s.t_start);
    for (; i + 1 < fixes.size() && fixes[i].t < s.t_end; ++i) {
      const TimeNs lo = std::max(s.t_start, fixes[i].t), hi = std::min(s.t_end, fixes[i + 1].t);
      if (hi <= lo) continue;
      // Constant wheel speeds inside a segment: counts in proportion to time.
      const double frac = static_cast<double>(hi - lo) / dur;
      t.legs[i].push_back({frac * s.dn_left, frac * s.dn_right});
    }
  }
  return t;
}

}  // namespace odo::calib
