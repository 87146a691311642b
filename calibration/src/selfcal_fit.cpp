// fit_fixes: initial value, Gauss-Newton, outlier rejection with a robust re-check, held-out
// acceptance (the pipeline of selfcal.hpp).
#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <iterator>
#include <numeric>

#include "odo/calibration/selfcal.hpp"
#include "selfcal_model.hpp"

namespace odo::calib {
namespace {

using detail::Eval;
using detail::FitOut;
using detail::Mat3;
using detail::MatP;
using detail::Vec3;
using detail::VecP;

// fix_scores: per fix, the mean of chi2 / gate over the usable excursions touching it.
template <int N>
std::vector<double> fix_scores(const std::vector<Eval<N>>& ev, std::size_t n_fixes) {
  std::vector<double> sum(n_fixes, 0.0);
  std::vector<int> n(n_fixes, 0);
  for (const Eval<N>& e : ev) {
    if (!e.usable) continue;
    const double q = detail::chi2(e) / detail::gate(e);
    for (int f : {e.from, e.to}) {
      sum[static_cast<std::size_t>(f)] += q;
      ++n[static_cast<std::size_t>(f)];
    }
  }
  for (std::size_t i = 0; i < n_fixes; ++i)
    if (n[i] > 0) sum[i] /= n[i];
  return sum;
}

// chi2_per_dof: of the usable excursions between the fixes of `acc` at the estimate of f.
template <int N>
double chi2_per_dof(const FixTrack& t, const SelfCalConfig& c, const std::vector<int>& acc,
                    const FitOut<N>& f) {
  double chi = 0.0;
  int dof = 0;
  for (const Eval<N>& e : detail::evaluate_chain<N>(t, acc, f.p, c, true)) {
    if (!e.usable) continue;
    chi += detail::chi2(e);
    dof += e.dof;
  }
  return dof > 0 ? chi / dof : 0.0;
}

// worst_fix: the fix with the largest score above 1 at the estimate of f (-1: none).
template <int N>
int worst_fix(const FixTrack& t, const SelfCalConfig& c, const std::vector<int>& acc,
              const FitOut<N>& f) {
  const std::vector<double> sc =
      fix_scores(detail::evaluate_chain<N>(t, acc, f.p, c, true), t.fixes.size());
  int worst = -1;
  for (int i : acc)
    if (sc[static_cast<std::size_t>(i)] > 1.0 &&
        (worst < 0 || sc[static_cast<std::size_t>(i)] > sc[static_cast<std::size_t>(worst)]))
      worst = i;
  return worst;
}

// leave_one_out: the fix of `acc` whose removal leaves the smallest chi2 per dof (one fit each).
template <int N>
int leave_one_out(const FixTrack& t, const SelfCalConfig& c, const std::vector<int>& acc) {
  int best = -1;
  double best_chi = 0.0;
  for (int i : acc) {
    std::vector<int> trial;
    std::copy_if(acc.begin(), acc.end(), std::back_inserter(trial), [i](int k) { return k != i; });
    const FitOut<N> f = detail::fit_once<N>(t, trial, c, {});
    if (!f.ok) continue;
    const double chi = chi2_per_dof(t, c, trial, f);
    if (best < 0 || chi < best_chi) {
      best = i;
      best_chi = chi;
    }
  }
  return best;
}

// reject_outliers: fit; while a fix scores above 1, reject one and fit again (until two fixes
// remain). The rejected fix is the worst-scored one: that trusts the estimate, which outliers
// may have dragged far (seen in the 24 h soak: two fixes 0.5-5 m off in 21, the estimate at
// b = 288 mm, and 19 good fixes rejected one after the other). So when half of the fixes (at
// least 3) would go, the rejection starts again and each time removes the fix whose removal
// leaves the smallest chi2 per dof (leave-one-out: a fit per fix; with 10 % of the fixes
// corrupted, half of a window of 21 is almost never outliers, so this is rare).
template <int N>
Result<FitOut<N>> reject_outliers(const FixTrack& t, const SelfCalConfig& c, std::vector<int>& acc,
                                  std::vector<int>& rejected) {
  const std::vector<int> all = acc;
  const std::size_t give_up = std::max<std::size_t>(3, all.size() / 2);
  bool loo = false;
  for (;;) {
    FitOut<N> f = detail::fit_once<N>(t, acc, c, {});
    if (!f.ok)
      return make_error(Errc::kInvalidArgument, "the fit diverged (factors left [0.5, 1.5])");
    if (acc.size() <= 2) return f;
    int worst = worst_fix<N>(t, c, acc, f);
    if (worst < 0) return f;
    if (!loo && rejected.size() >= give_up) {
      loo = true;
      acc = all;
      rejected.clear();
      continue;
    }
    if (loo) worst = leave_one_out<N>(t, c, acc);
    rejected.push_back(worst);
    acc.erase(std::find(acc.begin(), acc.end(), worst));
  }
}

// recheck: a rejected fix comes back when both of its excursions pass the gate against the
// final estimate, with the estimate's own uncertainty added to S. True when any came back.
template <int N>
bool recheck(const FixTrack& t, const SelfCalConfig& c, const FitOut<N>& f, std::vector<int>& acc,
             std::vector<int>& rejected) {
  bool any = false;
  for (auto it = rejected.begin(); it != rejected.end();) {
    std::vector<int> trial = acc;
    trial.insert(std::upper_bound(trial.begin(), trial.end(), *it), *it);
    bool pass = true;
    for (const Eval<N>& e : detail::evaluate_chain<N>(t, trial, f.p, c, true)) {
      if (!e.usable || (e.from != *it && e.to != *it)) continue;
      pass = pass && detail::chi2(e, e.j * f.cov * e.j.transpose()) <= detail::gate(e);
    }
    if (pass) {
      acc = std::move(trial);
      it = rejected.erase(it);
      any = true;
    } else {
      ++it;
    }
  }
  return any;
}

// HeldOut: sums of chi2 of held-out predictions with the candidate and with the calibration in
// use, and their degrees of freedom.
struct HeldOut {
  double cand = 0.0, use = 0.0;
  int dof = 0;
};

// held_out_scores: adds the held-out excursions' (train[k] false) chi2 of the predictions with
// the candidate and with the calibration in use to `h`, both with S of the calibration in use.
template <int N>
void held_out_scores(const FixTrack& t, const SelfCalConfig& c, const std::vector<int>& acc,
                     const VecP<N>& cand, const std::vector<bool>& train, HeldOut& h) {
  const std::vector<Eval<N>> base =
      detail::evaluate_chain<N>(t, acc, detail::in_use<N>(c), c, true);
  const std::vector<Eval<N>> ev = detail::evaluate_chain<N>(t, acc, cand, c, false);
  for (std::size_t k = 0; k < ev.size(); ++k) {
    if (train[k] || !ev[k].usable) continue;
    Eval<N> e = ev[k];
    e.s = base[k].s;
    h.cand += detail::chi2(e);
    h.use += detail::chi2(base[k]);
    h.dof += e.dof;
  }
}

// summarise: excursion counts and the fit's chi2 per dof; train[k]: excursion k is in the
// estimate's fit, held[k]: it was predicted held out (by the estimate or by a fold's).
template <int N>
void summarise(const FixTrack& t, const SelfCalConfig& c, const std::vector<int>& acc,
               const VecP<N>& p, const std::vector<bool>& train, const std::vector<bool>& held,
               SelfCalResult& r) {
  const std::vector<Eval<N>> ev = detail::evaluate_chain<N>(t, acc, p, c, true);
  double chi = 0.0;
  int dof = 0;
  for (std::size_t k = 0; k < ev.size(); ++k) {
    if (!ev[k].usable) {
      ++r.excursions_skipped;
      continue;
    }
    if (held[k]) ++r.excursions_held_out;
    if (!train[k]) continue;
    ++r.excursions_fit;
    chi += detail::chi2(ev[k]);
    dof += ev[k].dof;
  }
  r.chi2_per_dof = dof > 0 ? chi / dof : 0.0;
}

// The distance scale m = (c_L + c_R) / 2 as a direction in p.
template <int N>
VecP<N> scale_direction() {
  VecP<N> a = VecP<N>::Zero();
  a.template head<3>() = Vec3(0.5, 0.5, 0.0);
  return a;
}

// given_scale: the covariance conditioned on m (Gaussian conditioning, Sigma - Sigma a a^T
// Sigma / (a^T Sigma a)): the uncertainty of what is left when the scale is known, which the
// acceptance bounds test (the scale's own is the prior's at most).
template <int N>
MatP<N> given_scale(const MatP<N>& cov) {
  const VecP<N> a = scale_direction<N>(), sa = cov * a;
  return cov - sa * sa.transpose() / a.dot(sa);
}

// scale_learnt: 1 - var(m) / prior var(m): the share of the scale's information that came from
// the fixes (0: a dock drive, the prior's scale kept; towards 1: open drives).
template <int N>
double scale_learnt(const SelfCalConfig& c, const MatP<N>& cov) {
  const double prior = 0.5 * c.prior_sigma_factor * c.prior_sigma_factor;
  const VecP<N> a = scale_direction<N>();
  return std::clamp(1.0 - a.dot(cov * a) / prior, 0.0, 1.0);
}

// The acceptance folds: which excursions were predicted held out, the summed scores and the
// candidate (on entry: the fit on all excursions).
template <int N>
struct Folds {
  std::vector<bool> held;
  HeldOut scores;
  FitOut<N> candidate;
};

// score_folds: excursion k (time order) is held out by fold k % hold_out_every. kHoldOut scores
// the last fold's training fit and makes it the candidate; kCrossValidated scores every fold's
// training fit on its held-out excursions and keeps the fit on all as the candidate.
template <int N>
Status score_folds(const FixTrack& t, const SelfCalConfig& c, const std::vector<int>& acc,
                   Folds<N>& out) {
  const std::size_t n_exc = out.held.size(), every = static_cast<std::size_t>(c.hold_out_every);
  const bool cv = c.acceptance == Acceptance::kCrossValidated;
  for (std::size_t fold = cv ? 0 : every - 1; every > 0 && fold < every; ++fold) {
    std::vector<bool> train(n_exc);
    for (std::size_t k = 0; k < n_exc; ++k) {
      train[k] = k % every != fold;
      out.held[k] = out.held[k] || !train[k];
    }
    FitOut<N> ff = detail::fit_once<N>(t, acc, c, train);
    if (!ff.ok) return make_error(Errc::kInvalidArgument, "the fit diverged on the training set");
    held_out_scores(t, c, acc, ff.p, train, out.scores);
    if (!cv) out.candidate = ff;
  }
  return Ok{};
}

// first_too_uncertain: the first of c_L, c_R, b (0..2) whose standard deviation given the
// scale is above its bound; -1: none.
int first_too_uncertain(const SelfCalConfig& c, const SelfCalResult& r) {
  const double bound[3] = {c.max_sigma_factor, c.max_sigma_factor, c.max_sigma_wheelbase};
  for (int i = 0; i < 3; ++i)
    if (r.sigma_given_scale[static_cast<std::size_t>(i)] > bound[i]) return i;
  return -1;
}

Verdict decide(const SelfCalConfig& c, const SelfCalResult& r) {
  if (r.excursions_held_out == 0) return Verdict::kNoHeldOut;
  if (r.too_uncertain >= 0) return Verdict::kTooUncertain;
  return r.score_candidate < (1.0 - c.min_improvement) * r.score_in_use ? Verdict::kAccepted
                                                                        : Verdict::kNotBetter;
}

// fill_estimate: the candidate's values, covariance (4 x 4, the x_ICR row and column zero when
// it is not fitted), standard deviations and x_ICR's observability into r.
template <int N>
void fill_estimate(const SelfCalConfig& c, const FitOut<N>& f, SelfCalResult& r) {
  r.initial = detail::to_factors<N>(f.initial);
  r.estimate = detail::to_factors<N>(f.p);
  const MatP<N> cond = given_scale<N>(f.cov);
  for (int i = 0; i < N; ++i)
    for (int j = 0; j < N; ++j) cov_at(r.covariance, i, j) = f.cov(i, j);
  // max(0, .): the conditioned variance of a direction the scale fixes is zero up to rounding.
  for (int i = 0; i < 3; ++i) {
    r.sigma[static_cast<std::size_t>(i)] = std::sqrt(f.cov(i, i));
    r.sigma_given_scale[static_cast<std::size_t>(i)] = std::sqrt(std::max(0.0, cond(i, i)));
  }
  r.scale_learnt = scale_learnt<N>(c, f.cov);
  r.iterations = f.iterations;
  r.x_icr = detail::x_icr_of<N>(f.p, c);
  if constexpr (N == 4) {
    r.sigma_x_icr = std::sqrt(f.cov(3, 3));
    r.x_icr_observable = r.sigma_x_icr <= c.max_sigma_x_icr;
  }
}

// fit: fit_fixes with N parameters (3: c_L, c_R, b; 4: and x_ICR).
template <int N>
Result<SelfCalResult> fit(const FixTrack& t, const SelfCalConfig& c) {
  std::vector<int> acc(t.fixes.size()), rejected;
  std::iota(acc.begin(), acc.end(), 0);
  auto all = reject_outliers<N>(t, c, acc, rejected);
  if (!all) return std::move(all).error();
  if (recheck<N>(t, c, *all, acc, rejected)) {
    all = detail::fit_once<N>(t, acc, c, {});
    if (!all->ok) return make_error(Errc::kInvalidArgument, "the fit diverged after re-check");
  }
  const std::size_t n_exc = acc.size() - 1;
  const bool cv = c.acceptance == Acceptance::kCrossValidated;
  Folds<N> folds{std::vector<bool>(n_exc, false), {}, *all};
  if (auto s = score_folds<N>(t, c, acc, folds); !s) return std::move(s).error();
  const FitOut<N>& f = folds.candidate;
  SelfCalResult r;
  fill_estimate<N>(c, f, r);
  r.fixes_used = static_cast<int>(acc.size());
  r.fixes_rejected = static_cast<int>(rejected.size());
  std::sort(rejected.begin(), rejected.end());
  r.rejected = rejected;
  std::vector<bool> in_fit(n_exc, true);
  if (!cv)
    for (std::size_t k = 0; k < n_exc; ++k) in_fit[k] = !folds.held[k];
  summarise<N>(t, c, acc, f.p, in_fit, folds.held, r);
  if (folds.scores.dof > 0) {
    r.score_candidate = folds.scores.cand / folds.scores.dof;
    r.score_in_use = folds.scores.use / folds.scores.dof;
  }
  r.too_uncertain = first_too_uncertain(c, r);
  r.verdict = decide(c, r);
  return r;
}

}  // namespace

Result<SelfCalResult> fit_fixes(const FixTrack& t, const SelfCalConfig& c) {
  if (auto s = check_selfcal_config(c); !s) return std::move(s).error();
  if (auto s = detail::check_track(t); !s) return std::move(s).error();
  return c.icr == IcrFit::kFit ? fit<4>(t, c) : fit<3>(t, c);
}

}  // namespace odo::calib
