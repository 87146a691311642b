// Self-calibration from fixes taken anywhere (issue 34): robots whose c_L, c_R and b are drawn
// at random (c off up to 0.6 %, b up to 1.5 %, geared and direct-drive encoders) drive 20
// excursions at 100 Hz with Chong-Kleeman wheel noise and get a 5 mm / 0.5 deg fix at the end of
// each (standing still 0.5 s there). calib::fit_fixes is compared with the exact-model
// Gauss-Newton (analysis::reference_fit) on the same data, and its reported covariance with the
// errors it really makes (coverage). Three drives: open clean, open with 10 % of the fixes
// 0.5-5 m off, and dock excursions (the truth drawn from the estimator's prior, whose scale
// they cannot see). Built twice: sim_selfcal_open (label sim, 12 seeds, statistical checks whose
// tolerances are derived below) and study_selfcal_open (label study, 300 seeds: issue 34's done
// means, the figures of BENCHMARKS.md).
#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <Eigen/LU>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <vector>

#include "odo/analysis/seed.hpp"
#include "odo/analysis/selfcal_tools.hpp"
#include "odo/calibration/selfcal.hpp"
#include "odo/odometry/error_model.hpp"
#include "odo/odometry/pose.hpp"

namespace odo {
namespace {

#if defined(ODO_SELFCAL_STUDY)
#define OPEN_SUITE SelfCalOpenStudy
// Seeds a drive kind. The 1-sigma coverage of n seeds (three parameters each, correlated) has a
// sampling sd of 5.7 points at n = 60 (measured: 20 blocks of 60 seeds of the clean open drive,
// 58.9-78.3 %, 7 of 20 outside 68.3 +- 5, the exact model's 8 of 20), so 60 seeds cannot test
// the +-5 band; 300 make it about 2 sd (5.7 / sqrt(5) = 2.6 points).
constexpr int kSeeds = 300;
// Excursions a drive: issue 34's logs had 20; 10 keep the study's 900 drives near five minutes.
constexpr int kExcursions = 10;
#else
#define OPEN_SUITE SelfCalOpen
constexpr int kSeeds = 12;
constexpr int kExcursions = 20;
#endif

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;

Vec3 vec(const calib::Factors& f) {
  return Vec3(f.c_l, f.c_r, f.wheelbase);
}
// mat: the (c_L, c_R, b) block of a parameter covariance, and a pose covariance.
Mat3 mat(const calib::ParamCov& c) {
  Mat3 m;
  for (int i = 0; i < 9; ++i) m(i / 3, i % 3) = calib::cov_at(c, i / 3, i % 3);
  return m;
}
Mat3 mat(const Cov3& c) {
  Mat3 m;
  for (int i = 0; i < 9; ++i) m(i / 3, i % 3) = c[static_cast<std::size_t>(i)];
  return m;
}

// Relative errors (c_L, c_R: the factor's error; b: error / true b).
Vec3 rel_error(const calib::Factors& est, const calib::Factors& truth) {
  return Vec3(est.c_l - truth.c_l, est.c_r - truth.c_r, est.wheelbase / truth.wheelbase - 1.0);
}

// One drive's outcome.
struct Run {
  Vec3 err_est, err_ref;            // relative errors
  Vec3 z, z_ref;                    // error / reported sigma, per parameter (estimator, reference)
  double chi2_per_dof = 0.0;        // of the estimator's own fit
  Vec3 sigma_ratio = Vec3::Ones();  // the estimator's reported sigma / the reference's
  double chi2 = 0.0;                // (p - truth)^T Sigma^-1 (p - truth), 3 dof
  int corrupted = 0, flagged_bad = 0, flagged_good = 0;
  calib::Verdict verdict = calib::Verdict::kNoHeldOut;
  int ref_iterations = 0, iterations = 0;
  double ref_chi2 = 0.0;            // the reference's own (p - truth)^T Sigma^-1 (p - truth)
  double fit_s = 0.0, ref_s = 0.0;  // CPU time of fit_fixes and of the reference [s]
};

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

Run run(const analysis::FixDriveOptions& o, bool with_reference) {
  const analysis::FixDrive d = analysis::simulate_fix_drive(o);
  const calib::SelfCalConfig c = analysis::fix_drive_config(d, o);
  auto track = calib::build_track(d.segments, d.fixes);
  EXPECT_TRUE(track) << track.error().message;
  const auto t0 = std::chrono::steady_clock::now();
  auto r = calib::fit_fixes(*track, c);
  EXPECT_TRUE(r) << r.error().message;
  Run out;
  out.fit_s = seconds_since(t0);
  if (!track || !r) return out;
  out.err_est = rel_error(r->estimate, d.truth);
  const Vec3 e = vec(r->estimate) - vec(d.truth);
  const Mat3 cov = mat(r->covariance);
  out.chi2 = e.dot(cov.ldlt().solve(e));
  for (int i = 0; i < 3; ++i) out.z(i) = e(i) / std::sqrt(cov(i, i));
  out.verdict = r->verdict;
  out.iterations = r->iterations;
  out.chi2_per_dof = r->chi2_per_dof;
  std::vector<bool> clean(d.fixes.size());
  for (std::size_t i = 0; i < d.fixes.size(); ++i) {
    clean[i] = !d.corrupted[i];
    out.corrupted += d.corrupted[i] ? 1 : 0;
  }
  for (int i : r->rejected)
    (d.corrupted[static_cast<std::size_t>(i)] ? out.flagged_bad : out.flagged_good)++;
  if (with_reference) {
    // The reference is told which fixes are corrupted (an oracle): the yardstick of accuracy.
    const auto t1 = std::chrono::steady_clock::now();
    const analysis::ReferenceFit ref = analysis::reference_fit(*track, c, clean);
    out.ref_s = seconds_since(t1);
    out.err_ref = rel_error(ref.estimate, d.truth);
    out.ref_iterations = ref.iterations;
    const Vec3 er = vec(ref.estimate) - vec(d.truth);
    out.ref_chi2 = er.dot(mat(ref.covariance).ldlt().solve(er));
    for (int i = 0; i < 3; ++i) {
      out.z_ref(i) = er(i) / std::sqrt(mat(ref.covariance)(i, i));
      out.sigma_ratio(i) = std::sqrt(cov(i, i) / mat(ref.covariance)(i, i));
    }
  }
  return out;
}

double quantile(std::vector<double> v, double q) {
  std::sort(v.begin(), v.end());
  const double pos = q * static_cast<double>(v.size() - 1);
  const auto i = static_cast<std::size_t>(pos);
  const double f = pos - static_cast<double>(i);
  return i + 1 < v.size() ? v[i] * (1 - f) + v[i + 1] * f : v[i];
}

// Summary of a scenario over its seeds.
struct Summary {
  double cover1 = 0.0, cover2 = 0.0;  // fraction of |z| <= 1, <= 2 over seeds and parameters
  double ref_cover1 = 0.0, ref_cover2 = 0.0, chi2_per_dof = 0.0;
  double mean_chi2 = 0.0, mean_ref_chi2 = 0.0, fit_s = 0.0, ref_s = 0.0, ref_iterations = 0.0,
         iterations = 0.0;
  Vec3 med_est, med_ref, p90_est, p90_ref, sigma_ratio;
  int corrupted = 0, flagged_bad = 0, flagged_good = 0, seeds = 0;
};

Summary summarise(const char* name, const std::vector<Run>& runs, bool with_reference) {
  Summary s;
  s.seeds = static_cast<int>(runs.size());
  for (const Run& r : runs) {
    for (int i = 0; i < 3; ++i) {
      s.cover1 += std::fabs(r.z(i)) <= 1.0 ? 1.0 : 0.0;
      s.cover2 += std::fabs(r.z(i)) <= 2.0 ? 1.0 : 0.0;
      s.ref_cover1 += std::fabs(r.z_ref(i)) <= 1.0 ? 1.0 : 0.0;
      s.ref_cover2 += std::fabs(r.z_ref(i)) <= 2.0 ? 1.0 : 0.0;
    }
    s.mean_chi2 += r.chi2;
    s.mean_ref_chi2 += r.ref_chi2;
    s.corrupted += r.corrupted;
    s.flagged_bad += r.flagged_bad;
    s.flagged_good += r.flagged_good;
    s.fit_s += r.fit_s / static_cast<double>(runs.size());
    s.ref_s += r.ref_s / static_cast<double>(runs.size());
    s.ref_iterations += r.ref_iterations / static_cast<double>(runs.size());
    s.iterations += r.iterations / static_cast<double>(runs.size());
    s.chi2_per_dof += r.chi2_per_dof / static_cast<double>(runs.size());
  }
  s.cover1 /= 3.0 * s.seeds;
  s.cover2 /= 3.0 * s.seeds;
  s.ref_cover1 /= 3.0 * s.seeds;
  s.ref_cover2 /= 3.0 * s.seeds;
  s.mean_chi2 /= s.seeds;
  s.mean_ref_chi2 /= s.seeds;
  for (int i = 0; i < 3; ++i) {
    std::vector<double> a, b, q;
    for (const Run& r : runs) {
      q.push_back(r.sigma_ratio(i));
      a.push_back(std::fabs(r.err_est(i)));
      b.push_back(std::fabs(r.err_ref(i)));
    }
    s.med_est(i) = quantile(a, 0.5);
    s.p90_est(i) = quantile(a, 0.9);
    s.med_ref(i) = quantile(b, 0.5);
    s.p90_ref(i) = quantile(b, 0.9);
    s.sigma_ratio(i) = quantile(q, 0.5);
  }
  std::printf(
      "%s, %d seeds: coverage 1 sigma %.1f %%, 2 sigma %.1f %%, mean chi2(3) %.2f; fixes "
      "corrupted %d, flagged %d of them and %d good; fit %.3f s (%.1f iterations), reference %.3f "
      "s a seed\n",
      name, s.seeds, 100 * s.cover1, 100 * s.cover2, s.mean_chi2, s.corrupted, s.flagged_bad,
      s.flagged_good, s.fit_s, s.iterations, s.ref_s);
  if (with_reference)
    std::printf(
        "  reference: mean chi2(3) %.2f, coverage 1 sigma %.1f %%, 2 sigma %.1f %%, %.1f "
        "iterations; the estimator's fit chi2/dof %.2f\n",
        s.mean_ref_chi2, 100 * s.ref_cover1, 100 * s.ref_cover2, s.ref_iterations, s.chi2_per_dof);
  const char* names[] = {"c_L", "c_R", "b"};
  for (int i = 0; with_reference && i < 3; ++i)
    std::printf(
        "  %-3s |error| median %.2e (reference %.2e, ratio %.2f), 90th pct %.2e (%.2e, "
        "%.2f); reported sigma / reference's: median %.3f\n",
        names[i], s.med_est(i), s.med_ref(i), s.med_est(i) / s.med_ref(i), s.p90_est(i),
        s.p90_ref(i), s.p90_est(i) / s.p90_ref(i), s.sigma_ratio(i));
  return s;
}

std::vector<Run> drives(analysis::FixDriveOptions o, std::uint64_t stream, bool with_reference) {
  std::vector<Run> runs;
  for (int i = 0; i < kSeeds; ++i) {
    o.seed = analysis::seed_of(stream, static_cast<std::uint64_t>(i));
    o.direct_drive = i % 2 == 1;
    runs.push_back(run(o, with_reference));
  }
  return runs;
}

// Excursion: one excursion's odometry error with the true parameters from the true start pose
// (r = true end - predicted end), the Chong-Kleeman covariance q both fits propagate for it, and
// the Jacobian jp of the predicted end pose with respect to (c_L, c_R, b).
struct Excursion {
  Vec3 r;
  Mat3 q, jp;
};

std::vector<Excursion> excursions_of(const analysis::FixDrive& d, const calib::SelfCalConfig& c,
                                     const calib::FixTrack& t) {
  std::vector<Excursion> out;
  for (std::size_t k = 0; k + 1 < t.fixes.size(); ++k) {
    Excursion e;
    Pose2 p = d.true_poses[k];
    Cov3 cov{};
    for (const calib::LegCounts& lc : t.legs[k]) {
      const double d_l = d.truth.c_l * c.metres_per_count * lc.n_left;
      const double d_r = d.truth.c_r * c.metres_per_count * lc.n_right;
      propagate_arc(cov, p.theta, d_l, d_r, d.truth.wheelbase, c.odometry_noise);
      p = arc_step(p, d_l, d_r, d.truth.wheelbase);
    }
    const Pose2& b = d.true_poses[k + 1];
    e.r = Vec3(b.x - p.x, b.y - p.y, wrap_angle(b.theta - p.theta));
    e.q = mat(cov);
    for (int v = 0; v < 3; ++v) {
      const double h = v < 2 ? 1e-6 : 1e-7;  // central differences, as analysis::reference_fit
      calib::Factors fp = d.truth, fm = d.truth;
      (v == 0 ? fp.c_l : v == 1 ? fp.c_r : fp.wheelbase) += h;
      (v == 0 ? fm.c_l : v == 1 ? fm.c_r : fm.wheelbase) -= h;
      const Pose2 pp = calib::predict_excursion(d.true_poses[k], t.legs[k], fp, c.metres_per_count);
      const Pose2 pm = calib::predict_excursion(d.true_poses[k], t.legs[k], fm, c.metres_per_count);
      e.jp.col(v) = Vec3(pp.x - pm.x, pp.y - pm.y, wrap_angle(pp.theta - pm.theta)) / (2 * h);
    }
    out.push_back(e);
  }
  return out;
}

// The coverage of the fits rests on the propagated wheel-noise covariance being the one the
// simulator's noise (sim::WheelNoise, k sqrt(|d|) per physics step on the true travel) causes.
// Checked where the parameters learn from it: over 40 drives (400 excursions) with the true
// parameters and true start poses, (1) r^T q^-1 r is chi-square with 3 dof (mean 3, variance 6:
// the mean over n has sd sqrt(6 / n)); (2) for each parameter i the score g_i = (jp^T q^-1 r)_i
// is N(0, F_i) with F_i = (jp^T q^-1 jp)_ii, so sum g_i^2 / sum F_i has mean 1 and sd
// sqrt(2 sum F_i^2) / sum F_i. Both within 4 sd. Measured 2026-11-28: mean chi2 3.05 (sd 0.12),
// score ratios 1.07, 0.96, 1.16 (sd 0.08, 0.08, 0.09); a scratch run over 1000 excursions of
// other seeds: 3.07; 1.08, 1.02, 0.96. A model 1.5x too wide in variance would give 2.0.
TEST(OPEN_SUITE, TheModelledWheelNoiseIsTheSimulatedOne) {
  double chi2 = 0.0;
  Vec3 g2 = Vec3::Zero(), f = Vec3::Zero(), f2 = Vec3::Zero();
  int n = 0;
  for (int i = 0; i < 40; ++i) {
    analysis::FixDriveOptions o;
    o.excursions = 10;
    o.seed = analysis::seed_of(3404, static_cast<std::uint64_t>(i));
    o.direct_drive = i % 2 == 1;
    const analysis::FixDrive d = analysis::simulate_fix_drive(o);
    const calib::SelfCalConfig c = analysis::fix_drive_config(d, o);
    auto track = calib::build_track(d.segments, d.fixes);
    ASSERT_TRUE(track) << track.error().message;
    for (const Excursion& e : excursions_of(d, c, *track)) {
      const Mat3 w = e.q.inverse();
      chi2 += e.r.dot(w * e.r);
      const Vec3 g = e.jp.transpose() * w * e.r;
      const Vec3 fi = (e.jp.transpose() * w * e.jp).diagonal();
      g2 += g.cwiseProduct(g);
      f += fi;
      f2 += fi.cwiseProduct(fi);
      ++n;
    }
  }
  chi2 /= n;
  std::printf(
      "wheel noise over %d excursions: mean chi2(3) %.3f (sd %.3f); score / Fisher %.3f %.3f %.3f "
      "(sd %.3f %.3f %.3f)\n",
      n, chi2, std::sqrt(6.0 / n), g2(0) / f(0), g2(1) / f(1), g2(2) / f(2),
      std::sqrt(2.0 * f2(0)) / f(0), std::sqrt(2.0 * f2(1)) / f(1), std::sqrt(2.0 * f2(2)) / f(2));
  EXPECT_NEAR(chi2, 3.0, 4.0 * std::sqrt(6.0 / n));
  for (int i = 0; i < 3; ++i)
    EXPECT_NEAR(g2(i) / f(i), 1.0, 4.0 * std::sqrt(2.0 * f2(i)) / f(i)) << "parameter " << i;
}

// expect_calibrated: the covariance describes the errors. If it does, (p - truth)^T Sigma^-1
// (p - truth) is chi-square with 3 dof (mean 3, variance 6), so the mean over n seeds has
// standard deviation sqrt(6 / n); the bound is 4 of those.
void expect_calibrated(double mean_chi2) {
  EXPECT_NEAR(mean_chi2, 3.0, 4.0 * std::sqrt(6.0 / kSeeds));
}

#if defined(ODO_SELFCAL_STUDY)
// Issue 34's done means: coverage of 1 and 2 sigma within 5 points of 68.3 % and 95.4 %.
void expect_coverage(const Summary& s) {
  EXPECT_NEAR(s.cover1, 0.683, 0.05);
  EXPECT_NEAR(s.cover2, 0.954, 0.05);
}
// ... and |error| of c_L, c_R, b within 1.5 x the exact model's, median and 90th percentile.
void expect_as_good_as_the_reference(const Summary& s) {
  for (int i = 0; i < 3; ++i) {
    EXPECT_LE(s.med_est(i), 1.5 * s.med_ref(i)) << "parameter " << i;
    EXPECT_LE(s.p90_est(i), 1.5 * s.p90_ref(i)) << "parameter " << i;
  }
}
#else
void expect_coverage(const Summary& s) {
  expect_calibrated(s.mean_chi2);
}
void expect_as_good_as_the_reference(const Summary&) {}
#endif

TEST(OPEN_SUITE, OpenExcursionsLearnTheScaleAsWellAsTheExactModel) {
  analysis::FixDriveOptions o;
  o.excursions = kExcursions;
  const Summary s = summarise("open, clean", drives(o, 3401, true), true);
  // The yardstick first: the exact-model Gauss-Newton's own covariance must describe its errors.
  expect_calibrated(s.mean_ref_chi2);
  expect_coverage(s);
  expect_as_good_as_the_reference(s);
}

TEST(OPEN_SUITE, OpenExcursionsWithOutliersLearnTheScale) {
  // 10 % of the fixes (not the first) 0.5-5 m off; the reference is told which (an oracle).
  analysis::FixDriveOptions o;
  o.excursions = kExcursions;
  o.outliers = 0.1;
  const Summary s = summarise("open, 10 % outliers", drives(o, 3402, true), true);
  EXPECT_EQ(s.flagged_bad, s.corrupted);
  expect_coverage(s);
  expect_as_good_as_the_reference(s);
}

TEST(OPEN_SUITE, DockExcursionsKeepThePriorScaleAndSayHowUncertainItIs) {
  // Excursions back to the dock cannot see the scale: its error is the prior's, so the truth is
  // drawn from the estimator's prior (c_L, c_R ~ N(1, 0.01^2), b ~ N(b_n, 0.02^2)) for the
  // covariance to be tested. No reference: without a prior its scale is undetermined.
  analysis::FixDriveOptions o;
  o.excursions = kExcursions;
  o.dock = true;
  const calib::SelfCalConfig defaults;
  o.prior_sigma_factor = defaults.prior_sigma_factor;
  o.prior_sigma_wheelbase = defaults.prior_sigma_wheelbase;
  const Summary s = summarise("dock", drives(o, 3403, false), false);
  expect_coverage(s);
}

}  // namespace
}  // namespace odo
