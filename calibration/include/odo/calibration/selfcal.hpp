// Self-calibration from absolute fixes (issue 18): every excursion between two absolute pose
// fixes is a calibration run, since the odometry between them is a known function of
// p = (c_L, c_R, b). Pure math: inputs as arguments, no I/O, no exceptions; runs off the loop
// thread (it allocates) in the daemon and in `odomctl calib fit-fixes`.
//
// Model: a segment with counts (n_L, n_R) moves the wheels d_L = c_L c_m n_L, d_R = c_R c_m n_R
// (UMBmark Eq. 6.35, c_m the nominal metres per count) and is one exact arc (odo::arc_step).
// Pipeline (fit_fixes):
//  1. Start value: the calibration in use (the prior's mean). The linear estimate of Antonelli,
//     Chiaverini & Fusco 2005 (heading change between heading fixes linear in (u_R, u_L) =
//     (c_R/b, c_L/b); with those the position change linear in (c_L, c_R); b = LS fit of
//     (c_L, c_R) = b (u_L, u_R)) is reported as `initial`: as a start it was 3-12 % off on open
//     drives and Gauss-Newton stalled at the box's edge from there (issue 34).
//  2. Gauss-Newton on the exact model with analytic Jacobians, residual = fix - prediction.
//     An excursion's residual covariance is S = Sigma_end + G Sigma_start G^T + Sigma_odo: the
//     end fix's covariance, the start fix's propagated through the excursion (G = d end /
//     d start) and the Chong-Kleeman wheel noise along the excursion. Consecutive excursions
//     share a fix, so their residuals correlate: Cov(r_k, r_k+1) = -Sigma_fix G_k+1^T. The fit
//     is weighted by that joint (block-tridiagonal) covariance (with per-excursion weights the
//     reported sigma was 19 % too small against a Monte Carlo), evaluated at the estimate of
//     the pass before (three passes; frozen at the start it left open drives 4-6 sigma off),
//     plus the prior N(calibration in use, diag(prior_sigma_factor^2 (c_L, c_R),
//     prior_sigma_wheelbase^2)): the user's tolerance of the values in use (e.g. of the wheel
//     diameter), which also keeps unobservable directions (spins only, straights only, the
//     scale of dock drives) finite. The covariance is that posterior's. A step that would
//     leave the plausible box (factors 0.5 .. 1.5, b within 0.5 .. 2 times the in-use b) is
//     halved until it does not.
//  3. Outliers: a fix's score is the mean over the (at most two) excursions touching it of
//     chi2 / gate(dof), chi2 = r^T S^-1 r of the fitted estimate, gate = chi-square 99.9 %
//     quantile (13.82 for x, y; 16.27 for x, y, theta). While the largest score exceeds 1, that
//     fix is rejected (its two excursions merge into one) and the fit is redone. Robust
//     re-check: each rejected fix is tested again against the final estimate (both of its
//     excursions within the gate, with the parameter uncertainty added to S) and re-admitted
//     if it passes, followed by one more fit. When half of the fixes (at least 3) would be
//     rejected, the outliers have dragged the estimate (24 h soak: b = 288 mm, 19 good fixes
//     rejected): the rejection starts again, removing each time the fix whose removal leaves
//     the smallest chi2 per dof (leave-one-out).
//  4. Scale: excursions that end where they started (a dock) cannot see the distance scale:
//     multiplying c_L, c_R and b by one factor scales the closed path about its start. Fixes
//     away from the start (a map, a surveyed point, GNSS) see it. The prior decides in between:
//     a dock drive keeps the prior's scale (the values in use, prior_sigma_factor), an open drive
//     learns it, and the posterior covariance says how much (scale_learnt); nothing switches.
//  5. Acceptance: excursion k (in time order, after rejection) belongs to fold
//     k % hold_out_every. The score of a parameter set is the mean chi2 per degree of freedom
//     of its predictions of held-out excursions (S of the calibration in use for both).
//     kHoldOut: only the last fold is held out; the candidate is the fit on the other
//     excursions and is scored on that fold. kCrossValidated (default): every fold is held out
//     in turn, each excursion predicted by the fit of the other folds; the
//     candidate is the fit on all excursions, which has hold_out_every / (hold_out_every - 1)
//     times the training data (issue 18's LabMate: E_max,syst 11.6 -> 8.2 mm, BENCHMARKS.md).
//     The cross-validated score judges the estimator on excursions it did not see; the
//     candidate itself saw them all. The candidate is accepted only when every standard
//     deviation given the scale (sigma_given_scale: c_L, c_R below max_sigma_factor, b below
//     max_sigma_wheelbase) is within its bound AND the score is lower than (1 - min_improvement)
//     times the calibration in use's (a margin: near the truth two calibrations score alike,
//     and without it a 24 h soak wrote 45 records, 19 of them worse than the one before by
//     E_max,syst). The bounds do not apply to the scale: its posterior is never wider than the
//     prior, so a dock drive writes the ratio and the turn rates with the prior's scale, and an
//     open drive writes the scale as far as its fixes determined it.
// x_ICR (issue 38, IcrFit::kFit): a 4th parameter, the skid-steer ICR offset; an excursion from
// heading theta0 to theta1 then ends x (u(theta0) - u(theta1)) from the plain arcs' end
// (selfcal_model.cpp), so only net turns other than 0 and 2 pi show it; it is reported
// observable (to be applied) when its posterior sigma is at most max_sigma_x_icr.
// Fix headings are used where present. A fix without heading contributes x, y only; the next
// excursion then starts with the heading predicted by the previous one (its derivative carried
// along, its variance taken as that of the last heading fix: that heading's correlation with
// the previous excursion's residual is neglected). An excursion whose start heading is unknown
// altogether is skipped.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "odo/calibration/count_recorder.hpp"
#include "odo/calibration/icr_fit.hpp"
#include "odo/calibration/umbmark.hpp"
#include "odo/hal/result.hpp"
#include "odo/hal/time.hpp"
#include "odo/odometry/error_model.hpp"
#include "odo/odometry/pose.hpp"

namespace odo::calib {

// An absolute pose fix in the odometry's world frame, for the instant t.
struct PoseFix {
  TimeNs t = 0;                 // the time the fix refers to, on the loop's clock [ns]
  double x = 0.0;               // [m]
  double y = 0.0;               // [m]
  std::optional<double> theta;  // [rad]; nullopt: heading unknown
  double sigma_xy = 0.0;        // standard deviation of x and of y [m], > 0
  double sigma_theta = 0.0;     // [rad], > 0 when theta is given
};

// Counts of one segment of an excursion (fractional after a split at a fix time).
struct LegCounts {
  double n_left = 0.0;
  double n_right = 0.0;
};

// The data of a fit: fixes in time order and the segments between consecutive fixes
// (legs[i] lies between fixes[i] and fixes[i + 1]).
struct FixTrack {
  std::vector<PoseFix> fixes;
  std::vector<std::vector<LegCounts>> legs;
};

// build_track: assigns recorded segments (time order, contiguous or with standstill gaps) to
// the intervals between the fixes (time order, strictly increasing t); a segment straddling a
// fix time is split in proportion to time. Errors name the fix or segment out of order.
Result<FixTrack> build_track(std::span<const CountSegment> segments,
                             std::span<const PoseFix> fixes);

// How the held-out acceptance test is run (step 5 above).
enum class Acceptance : std::uint8_t {
  kHoldOut = 0,         // one fold held out; the candidate is the fit on the rest
  kCrossValidated = 1,  // every fold held out in turn; the candidate is the fit on all
};

// Covariance of (c_L, c_R, b, x_ICR), row-major 4 x 4 [-, -, m, m; ...; m^2]; the x_ICR row and
// column are zero when it is not fitted (IcrFit::kFixed).
using ParamCov = std::array<double, 16>;
// cov_at: element (i, j) of c (0 c_L, 1 c_R, 2 b, 3 x_ICR).
constexpr double& cov_at(ParamCov& c, int i, int j) {
  return c[static_cast<std::size_t>(4 * i + j)];
}
constexpr double cov_at(const ParamCov& c, int i, int j) {
  return c[static_cast<std::size_t>(4 * i + j)];
}

struct SelfCalConfig {
  double metres_per_count = 0.0;     // c_m, nominal [m/count] (Kinematics::metres_per_count)
  Factors in_use{1.0, 1.0, 0.0};     // calibration in use: prior mean and the acceptance baseline
  double prior_sigma_factor = 0.01;  // prior standard deviation of c_L, c_R
  double prior_sigma_wheelbase = 0.02;  // [m]
  ErrorModelParams odometry_noise{};    // wheel noise k_L, k_R [m^(1/2)] in S
  int max_iterations = 20;              // Gauss-Newton
  int hold_out_every = 4;               // folds of the acceptance (step 5); 0: none (no decision)
  Acceptance acceptance = Acceptance::kCrossValidated;
  double max_sigma_factor = 2e-4;     // acceptance bound on sigma(c_L), sigma(c_R)
  double max_sigma_wheelbase = 2e-4;  // [m] acceptance bound on sigma(b)
  // The held-out score must be below (1 - min_improvement) times the in-use calibration's: a
  // candidate about as good as the calibration in use is not written (0 .. 0.9).
  double min_improvement = 0.1;
  // The ICR offset: in use [m] (+ ahead of the centre; the model's in both modes), fitted or not,
  // its prior standard deviation and the bound on its posterior one below which the fit applies
  // it (above: not observable from these fixes; c_L, c_R, b are judged as usual).
  IcrFit icr = IcrFit::kFixed;
  double x_icr = 0.0;              // [m], within KinematicLimits::kXIcr
  double prior_sigma_x_icr = 0.1;  // [m]
  double max_sigma_x_icr = 0.002;  // [m]
};

// check_selfcal_config: every field finite and in range; the message names the field.
Status check_selfcal_config(const SelfCalConfig& c);

// Why a candidate was or was not accepted.
enum class Verdict : std::uint8_t {
  kAccepted = 0,
  kTooUncertain = 1,  // a standard deviation above its bound
  kNotBetter = 2,     // held-out score not below (1 - min_improvement) x the calibration in use
  kNoHeldOut = 3,     // nothing held out (hold_out_every = 0 or too few excursions)
};

inline constexpr Choice<Verdict> kVerdictNames[] = {{Verdict::kAccepted, "accepted"},
                                                    {Verdict::kTooUncertain, "too-uncertain"},
                                                    {Verdict::kNotBetter, "not-better"},
                                                    {Verdict::kNoHeldOut, "no-held-out"}};

// verdict_name: v's spelling in kVerdictNames ("accepted", "too-uncertain", ...).
const char* verdict_name(Verdict v) noexcept;

struct SelfCalResult {
  Factors initial;                // Antonelli et al. linear estimate (reported, not the start)
  Factors estimate;               // Gauss-Newton on the training excursions, with the prior
  ParamCov covariance{};          // of estimate (posterior: prior and fixes)
  std::array<double, 3> sigma{};  // sqrt of the diagonal: c_L, c_R, b [-, -, m]
  std::array<double, 3> sigma_given_scale{};  // the same with m = (c_L + c_R)/2 known: what the
                                              // acceptance bounds test
  double scale_learnt = 0.0;  // 1 - var(m) / prior var(m): 0 the prior's scale, 1 the fixes'
  int too_uncertain = -1;     // kTooUncertain: c_L, c_R, b (0..2) the first over its bound
  int iterations = 0;         // Gauss-Newton iterations of the last fit (all passes)
  int fixes_used = 0;         // accepted fixes
  int fixes_rejected = 0;
  std::vector<int> rejected;     // indices into FixTrack::fixes
  int excursions_fit = 0;        // in the candidate's fit
  int excursions_held_out = 0;   // predicted held out (kCrossValidated: every usable one)
  int excursions_skipped = 0;    // start heading unknown
  double chi2_per_dof = 0.0;     // of the fit on its own excursions
  double score_candidate = 0.0;  // held-out mean chi2 per dof (of the folds' fits)
  double score_in_use = 0.0;
  Verdict verdict = Verdict::kNoHeldOut;
  // x_ICR: kFit's estimate and standard deviation, or the value in use and 0 (kFixed).
  // x_icr_observable: fitted and sigma_x_icr <= max_sigma_x_icr, so that an accepted candidate
  // carries it; false: the value in use stays (the reason: sigma_x_icr against the bound).
  double x_icr = 0.0;        // [m]
  double sigma_x_icr = 0.0;  // [m]
  bool x_icr_observable = false;
};

// fit_fixes: the whole pipeline above. Errors: invalid config, a fix with a non-positive or
// non-finite sigma, fewer than two fixes, a diverging fit (factors outside [0.5, 1.5]).
Result<SelfCalResult> fit_fixes(const FixTrack& track, const SelfCalConfig& cfg);

// predict_excursion: the pose at the end of `legs` from `start` [m, m, rad] with parameters f
// and the ICR offset x_icr [m] (exact arcs, arc_step_icr); for tests and tools.
Pose2 predict_excursion(const Pose2& start, std::span<const LegCounts> legs, const Factors& f,
                        double metres_per_count, double x_icr = 0.0);

}  // namespace odo::calib
