// Self-calibration from fixes taken anywhere (issue 34): robots whose c_L, c_R and b are drawn
// at random (c off up to 0.6 %, b up to 1.5 %, geared and direct-drive encoders) drive 20
// excursions at 100 Hz with Chong-Kleeman wheel noise and get a 5 mm / 0.5 deg fix at the end of
// each (standing still 0.5 s there). calib::fit_fixes is compared with the exact-model
// Gauss-Newton (analysis::reference_fit) on the same data, and its reported covariance with the
// errors it really makes (coverage). Built twice: sim_selfcal_open (label sim, few seeds, a
// statistical check whose tolerances are derived below) and study_selfcal_open (label study,
// the figures of BENCHMARKS.md).
#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "odo/analysis/seed.hpp"
#include "odo/analysis/selfcal_tools.hpp"
#include "odo/calibration/selfcal.hpp"

namespace odo {
namespace {

#if defined(ODO_SELFCAL_STUDY)
#define OPEN_SUITE SelfCalOpenStudy
constexpr int kSeeds = 60;
#else
#define OPEN_SUITE SelfCalOpen
constexpr int kSeeds = 12;
#endif

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;

Vec3 vec(const calib::Factors& f) {
  return Vec3(f.c_l, f.c_r, f.wheelbase);
}
Mat3 mat(const calib::ParamCov& c) {
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
  Vec3 err_est, err_ref;  // relative errors
  Vec3 z;                 // error / reported sigma, per parameter
  double chi2 = 0.0;      // (p - truth)^T Sigma^-1 (p - truth), 3 dof
  int corrupted = 0, flagged_bad = 0, flagged_good = 0;
  calib::Verdict verdict = calib::Verdict::kNoHeldOut;
  int ref_iterations = 0;
  double ref_chi2 = 0.0;  // the reference's own (p - truth)^T Sigma^-1 (p - truth)
};

Run run(const analysis::FixDriveOptions& o, bool with_reference) {
  const analysis::FixDrive d = analysis::simulate_fix_drive(o);
  const calib::SelfCalConfig c = analysis::fix_drive_config(d, o);
  auto track = calib::build_track(d.segments, d.fixes);
  EXPECT_TRUE(track) << track.error().message;
  auto r = calib::fit_fixes(*track, c);
  EXPECT_TRUE(r) << r.error().message;
  Run out;
  if (!track || !r) return out;
  out.err_est = rel_error(r->estimate, d.truth);
  const Vec3 e = vec(r->estimate) - vec(d.truth);
  const Mat3 cov = mat(r->covariance);
  out.chi2 = e.dot(cov.ldlt().solve(e));
  for (int i = 0; i < 3; ++i) out.z(i) = e(i) / std::sqrt(cov(i, i));
  out.verdict = r->verdict;
  std::vector<bool> clean(d.fixes.size());
  for (std::size_t i = 0; i < d.fixes.size(); ++i) {
    clean[i] = !d.corrupted[i];
    out.corrupted += d.corrupted[i] ? 1 : 0;
  }
  for (int i : r->rejected)
    (d.corrupted[static_cast<std::size_t>(i)] ? out.flagged_bad : out.flagged_good)++;
  if (with_reference) {
    // The reference is told which fixes are corrupted (an oracle): the yardstick of accuracy.
    const analysis::ReferenceFit ref = analysis::reference_fit(*track, c, clean);
    out.err_ref = rel_error(ref.estimate, d.truth);
    out.ref_iterations = ref.iterations;
    const Vec3 er = vec(ref.estimate) - vec(d.truth);
    out.ref_chi2 = er.dot(mat(ref.covariance).ldlt().solve(er));
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
  double mean_chi2 = 0.0, mean_ref_chi2 = 0.0;
  Vec3 med_est, med_ref, p90_est, p90_ref;
  int corrupted = 0, flagged_bad = 0, flagged_good = 0, seeds = 0;
};

Summary summarise(const char* name, const std::vector<Run>& runs, bool with_reference) {
  Summary s;
  s.seeds = static_cast<int>(runs.size());
  for (const Run& r : runs) {
    for (int i = 0; i < 3; ++i) {
      s.cover1 += std::fabs(r.z(i)) <= 1.0 ? 1.0 : 0.0;
      s.cover2 += std::fabs(r.z(i)) <= 2.0 ? 1.0 : 0.0;
    }
    s.mean_chi2 += r.chi2;
    s.mean_ref_chi2 += r.ref_chi2;
    s.corrupted += r.corrupted;
    s.flagged_bad += r.flagged_bad;
    s.flagged_good += r.flagged_good;
  }
  s.cover1 /= 3.0 * s.seeds;
  s.cover2 /= 3.0 * s.seeds;
  s.mean_chi2 /= s.seeds;
  s.mean_ref_chi2 /= s.seeds;
  for (int i = 0; i < 3; ++i) {
    std::vector<double> a, b;
    for (const Run& r : runs) {
      a.push_back(std::fabs(r.err_est(i)));
      b.push_back(std::fabs(r.err_ref(i)));
    }
    s.med_est(i) = quantile(a, 0.5);
    s.p90_est(i) = quantile(a, 0.9);
    s.med_ref(i) = quantile(b, 0.5);
    s.p90_ref(i) = quantile(b, 0.9);
  }
  std::printf(
      "%s, %d seeds: coverage 1 sigma %.1f %%, 2 sigma %.1f %%, mean chi2(3) %.2f; fixes "
      "corrupted %d, flagged %d of them and %d good\n",
      name, s.seeds, 100 * s.cover1, 100 * s.cover2, s.mean_chi2, s.corrupted, s.flagged_bad,
      s.flagged_good);
  if (with_reference) std::printf("  reference: mean chi2(3) %.2f\n", s.mean_ref_chi2);
  const char* names[] = {"c_L", "c_R", "b"};
  for (int i = 0; with_reference && i < 3; ++i)
    std::printf(
        "  %-3s |error| median %.2e (reference %.2e, ratio %.2f), 90th pct %.2e (%.2e, "
        "%.2f)\n",
        names[i], s.med_est(i), s.med_ref(i), s.med_est(i) / s.med_ref(i), s.p90_est(i),
        s.p90_ref(i), s.p90_est(i) / s.p90_ref(i));
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

TEST(OPEN_SUITE, OpenExcursionsLearnTheScaleAsWellAsTheExactModel) {
  analysis::FixDriveOptions o;
  const Summary s = summarise("open, clean", drives(o, 3401, true), true);
  // The yardstick first: the exact-model Gauss-Newton's own covariance must describe its errors.
  // If it does, (p - truth)^T Sigma^-1 (p - truth) is chi-square with 3 dof (mean 3, variance 6),
  // so the mean over n seeds has standard deviation sqrt(6 / n); the bound is 4 of those.
  EXPECT_NEAR(s.mean_ref_chi2, 3.0, 4.0 * std::sqrt(6.0 / kSeeds));
}

}  // namespace
}  // namespace odo
