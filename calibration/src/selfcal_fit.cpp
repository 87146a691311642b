// fit_fixes: initial value, Gauss-Newton, outlier rejection with a robust re-check, held-out
// acceptance (the pipeline of selfcal.hpp).
#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <numeric>

#include "odo/calibration/selfcal.hpp"
#include "selfcal_model.hpp"

namespace odo::calib {
namespace {

using detail::Eval;
using detail::FitOut;
using detail::Mat3;
using detail::Vec3;

// fix_scores: per fix, the mean of chi2 / gate over the usable excursions touching it.
std::vector<double> fix_scores(const std::vector<Eval>& ev, std::size_t n_fixes) {
  std::vector<double> sum(n_fixes, 0.0);
  std::vector<int> n(n_fixes, 0);
  for (const Eval& e : ev) {
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

// reject_outliers: fit, reject the fix with the largest score above 1, fit again, until every
// score is within the gate (or two fixes remain).
Result<FitOut> reject_outliers(const FixTrack& t, const SelfCalConfig& c, std::vector<int>& acc,
                               std::vector<int>& rejected) {
  for (;;) {
    FitOut f = detail::fit_once(t, acc, c, {});
    if (!f.ok)
      return make_error(Errc::kInvalidArgument, "the fit diverged (factors left [0.5, 1.5])");
    if (acc.size() <= 2) return f;
    const std::vector<double> sc =
        fix_scores(detail::evaluate_chain(t, acc, f.p, c, true), t.fixes.size());
    int worst = -1;
    for (int i : acc)
      if (sc[static_cast<std::size_t>(i)] > 1.0 &&
          (worst < 0 || sc[static_cast<std::size_t>(i)] > sc[static_cast<std::size_t>(worst)]))
        worst = i;
    if (worst < 0) return f;
    rejected.push_back(worst);
    acc.erase(std::find(acc.begin(), acc.end(), worst));
  }
}

// recheck: a rejected fix comes back when both of its excursions pass the gate against the
// final estimate, with the estimate's own uncertainty added to S. True when any came back.
bool recheck(const FixTrack& t, const SelfCalConfig& c, const FitOut& f, std::vector<int>& acc,
             std::vector<int>& rejected) {
  bool any = false;
  for (auto it = rejected.begin(); it != rejected.end();) {
    std::vector<int> trial = acc;
    trial.insert(std::upper_bound(trial.begin(), trial.end(), *it), *it);
    bool pass = true;
    for (const Eval& e : detail::evaluate_chain(t, trial, f.p, c, true)) {
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

// held_out_scores: mean chi2 per degree of freedom of the held-out excursions' predictions with
// the candidate and with the calibration in use, both with S of the calibration in use.
std::pair<double, double> held_out_scores(const FixTrack& t, const SelfCalConfig& c,
                                          const std::vector<int>& acc, const Vec3& cand,
                                          const std::vector<bool>& train) {
  const std::vector<Eval> base = detail::evaluate_chain(t, acc, detail::to_vec(c.in_use), c, true);
  const std::vector<Eval> ev = detail::evaluate_chain(t, acc, cand, c, false);
  double s_cand = 0.0, s_use = 0.0;
  int dof = 0;
  for (std::size_t k = 0; k < ev.size(); ++k) {
    if (train[k] || !ev[k].usable) continue;
    Eval e = ev[k];
    e.s = base[k].s;
    s_cand += detail::chi2(e);
    s_use += detail::chi2(base[k]);
    dof += e.dof;
  }
  if (dof == 0) return {0.0, 0.0};
  return {s_cand / dof, s_use / dof};
}

void summarise(const FixTrack& t, const SelfCalConfig& c, const std::vector<int>& acc,
               const std::vector<bool>& train, SelfCalResult& r) {
  const std::vector<Eval> ev = detail::evaluate_chain(t, acc, detail::to_vec(r.estimate), c, true);
  double chi = 0.0;
  int dof = 0;
  for (std::size_t k = 0; k < ev.size(); ++k) {
    if (!ev[k].usable) {
      ++r.excursions_skipped;
      continue;
    }
    if (!train[k]) {
      ++r.excursions_held_out;
      continue;
    }
    ++r.excursions_fit;
    chi += detail::chi2(ev[k]);
    dof += ev[k].dof;
  }
  r.chi2_per_dof = dof > 0 ? chi / dof : 0.0;
}

// hold_scale: when the distance scale m = (c_L + c_R) / 2 is not determined to
// max_sigma_factor (excursions that return to where they started cannot see it: scaling c_L,
// c_R and b together scales the whole closed path about its start), the candidate is
// conditioned on m = m_in_use (Gaussian conditioning: p += K (m_use - m), Sigma -= K a^T Sigma,
// K = Sigma a / (a^T Sigma a)), which keeps what the data do determine. True when it did.
bool hold_scale(const SelfCalConfig& c, FitOut& f) {
  const Vec3 a(0.5, 0.5, 0.0);
  const Vec3 sa = f.cov * a;
  const double var = a.dot(sa);
  if (std::sqrt(var) <= c.max_sigma_factor) return false;
  const Vec3 k = sa / var;
  f.p += k * (0.5 * (c.in_use.c_l + c.in_use.c_r) - a.dot(f.p));
  f.cov -= k * sa.transpose();
  return true;
}

Verdict decide(const SelfCalConfig& c, const SelfCalResult& r) {
  if (r.excursions_held_out == 0) return Verdict::kNoHeldOut;
  if (r.sigma[0] > c.max_sigma_factor || r.sigma[1] > c.max_sigma_factor ||
      r.sigma[2] > c.max_sigma_wheelbase)
    return Verdict::kTooUncertain;
  return r.score_candidate < r.score_in_use ? Verdict::kAccepted : Verdict::kNotBetter;
}

}  // namespace

Result<SelfCalResult> fit_fixes(const FixTrack& t, const SelfCalConfig& c) {
  if (auto s = check_selfcal_config(c); !s) return std::move(s).error();
  if (auto s = detail::check_track(t); !s) return std::move(s).error();
  std::vector<int> acc(t.fixes.size()), rejected;
  std::iota(acc.begin(), acc.end(), 0);
  auto all = reject_outliers(t, c, acc, rejected);
  if (!all) return std::move(all).error();
  if (recheck(t, c, *all, acc, rejected)) {
    all = detail::fit_once(t, acc, c, {});
    if (!all->ok) return make_error(Errc::kInvalidArgument, "the fit diverged after re-check");
  }
  // Hold out every hold_out_every-th excursion (time order) and fit the rest.
  std::vector<bool> train(acc.size() - 1, true);
  for (std::size_t k = 0; c.hold_out_every > 0 && k < train.size(); ++k)
    train[k] = (k % static_cast<std::size_t>(c.hold_out_every)) !=
               static_cast<std::size_t>(c.hold_out_every - 1);
  FitOut f = detail::fit_once(t, acc, c, train);
  if (!f.ok) return make_error(Errc::kInvalidArgument, "the fit diverged on the training set");
  SelfCalResult r;
  r.free_scale = detail::to_factors(f.p);
  r.scale_held = hold_scale(c, f);
  r.initial = detail::to_factors(f.initial);
  r.estimate = detail::to_factors(f.p);
  for (int i = 0; i < 9; ++i) r.covariance[static_cast<std::size_t>(i)] = f.cov(i / 3, i % 3);
  // max(0, .): the conditioned variance along the held direction is zero up to rounding.
  for (int i = 0; i < 3; ++i)
    r.sigma[static_cast<std::size_t>(i)] = std::sqrt(std::max(0.0, f.cov(i, i)));
  r.iterations = f.iterations;
  r.fixes_used = static_cast<int>(acc.size());
  r.fixes_rejected = static_cast<int>(rejected.size());
  std::sort(rejected.begin(), rejected.end());
  r.rejected = rejected;
  summarise(t, c, acc, train, r);
  std::tie(r.score_candidate, r.score_in_use) = held_out_scores(t, c, acc, f.p, train);
  r.verdict = decide(c, r);
  return r;
}

}  // namespace odo::calib
