// Self-calibration from dock fixes on the simulated LabMate (issue 18): true wheelbase 0.337 m
// against 0.340 nominal, diameter ratio 0.9985. The robot drives random excursions from a dock
// (turns on the spot, straights, arcs, then back to the dock); a fix of the true pose (plus its
// noise) is taken at the dock after every excursion. The loop's recording is done here by
// hand, tick by tick (SimEncoderSource + CountRecorder at 100 Hz), as the daemon will do it.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <random>
#include <set>
#include <vector>

#include "odo/analysis/selfcal_tools.hpp"
#include "odo/analysis/umbmark_tools.hpp"
#include "odo/calibration/count_recorder.hpp"
#include "odo/calibration/selfcal.hpp"
#include "odo/calibration/umbmark.hpp"
#include "odo/odometry/pose.hpp"
#include "odo/sim/floor.hpp"
#include "odo/sim/robot.hpp"
#include "odo/sim/sim_encoder.hpp"

namespace odo {
namespace {

using analysis::random_excursion;
using calib::Factors;
constexpr double kBn = analysis::kSelfCalBn;
constexpr TimeNs kTick = 10'000'000;  // 100 Hz
constexpr double kPi = std::numbers::pi;

const sim::RobotGeometry kTruthGeometry = sim::labmate_geometry(analysis::kSelfCalDn);

Factors true_factors() {
  return analysis::selfcal_truth();
}

Kinematics kinematics(const Factors& f) {
  return analysis::selfcal_kinematics(f);
}

struct Drive {
  std::vector<calib::CountSegment> segments;
  std::vector<calib::PoseFix> fixes;
  std::vector<Pose2> truth;  // true pose at every fix
};

struct DriveOptions {
  int excursions = 20;
  double sigma_xy = 0.0;  // fix noise [m]
  double sigma_th = 0.0;  // [rad]
  bool rough_floor = false;
  std::uint64_t seed = 1;
};

// drive: the excursions with a dock fix after each one (and one at the start).
Drive drive(const DriveOptions& o) {
  std::mt19937_64 rng(o.seed);
  std::normal_distribution<double> n01;
  calib::CountRecorder rec(*calib::recorder_limits(kinematics({1.0, 1.0, kBn})));
  Drive d;
  Pose2 pose;  // true pose, the dock at the origin
  TimeNs t0 = 0;
  auto take_fix = [&](TimeNs t) {
    d.truth.push_back(pose);
    // Declared sigmas of noise-free fixes: 0.1 mm, 0.1 mrad (a sigma must be positive).
    d.fixes.push_back({t, pose.x + o.sigma_xy * n01(rng), pose.y + o.sigma_xy * n01(rng),
                       wrap_angle(pose.theta + o.sigma_th * n01(rng)), std::max(o.sigma_xy, 1e-4),
                       std::max(o.sigma_th, 1e-4)});
  };
  rec.start(0);
  take_fix(0);
  for (int e = 0; e < o.excursions; ++e) {
    auto robot = *sim::SimRobot::create(kTruthGeometry, random_excursion(rng, pose), pose);
    sim::UmbmarkFloor::Options fo;
    fo.roughness_height = o.rough_floor ? analysis::kPaperRoughness : 0.0;
    sim::UmbmarkFloor floor(fo, o.seed * 1000 + static_cast<std::uint64_t>(e));
    robot.set_travel_perturbation(&floor);
    sim::SimEncoderSource enc(robot, 32);
    EncoderSample prev = enc.read(0);
    const TimeNs end = from_seconds(sim::scenario_duration(robot.scenario()) + 1.0);
    calib::CountSegment seg;
    TimeNs t = kTick;
    for (; t <= end; t += kTick) {
      const EncoderSample s = enc.read(t);
      if (rec.add_tick(t0 + t, s.left - prev.left, s.right - prev.right, seg))
        d.segments.push_back(seg);
      prev = s;
    }
    if (rec.flush(seg)) d.segments.push_back(seg);
    t0 += t - kTick;
    pose = robot.true_pose();
    take_fix(t0);
  }
  return d;
}

calib::SelfCalConfig config(bool noise) {
  calib::SelfCalConfig c;
  c.metres_per_count = kinematics({1.0, 1.0, kBn}).metres_per_count();
  c.in_use = {1.0, 1.0, kBn};
  if (!noise) c.odometry_noise = {1e-5, 1e-5};  // count quantisation only
  return c;
}

Result<calib::SelfCalResult> fit(const Drive& d, const calib::SelfCalConfig& c, std::size_t n) {
  auto t = calib::build_track(d.segments, std::span(d.fixes).first(n));
  if (!t) return std::move(t).error();
  return calib::fit_fixes(*t, c);
}

double e_max_syst(const Factors& f, bool rough) {
  return analysis::selfcal_e_max_syst(f, rough);
}

// The same file builds sim_selfcal (label sim) and study_selfcal (label target, with the open
// target test): distinct suite names keep their ctest names, and so their labels, apart.
#if defined(ODO_SELFCAL_STUDY)
#define SELFCAL_SUITE SelfCalStudy
#else
#define SELFCAL_SUITE SelfCalSim
#endif

double rel_err(double v, double truth) {
  return std::fabs(v / truth - 1.0);
}

TEST(SELFCAL_SUITE, NoiseFreeFixesWithinFiveHundredthsOfAPercent) {
  const Drive d = drive({20, 0.0, 0.0, false, 1});
  const Factors tr = true_factors();
  std::printf("truth c_l %.6f c_r %.6f b %.6f m; %zu segments for 20 excursions\n", tr.c_l, tr.c_r,
              tr.wheelbase, d.segments.size());
  for (std::size_t n : {3U, 5U, 9U, 21U}) {
    auto r = fit(d, config(false), n);
    ASSERT_TRUE(r) << r.error().message;
    std::printf(
        "%2zu excursions: c_l %+.4f %% c_r %+.4f %% b %+.4f %% (sigma %.2g %.2g, b %.3g mm) %s\n",
        n - 1, 100 * (r->estimate.c_l / tr.c_l - 1), 100 * (r->estimate.c_r / tr.c_r - 1),
        100 * (r->estimate.wheelbase / tr.wheelbase - 1), r->sigma[0], r->sigma[1],
        1e3 * r->sigma[2], calib::verdict_name(r->verdict));
    if (n == 21U) {
      EXPECT_LT(rel_err(r->estimate.c_l, tr.c_l), 5e-4);
      EXPECT_LT(rel_err(r->estimate.c_r, tr.c_r), 5e-4);
      EXPECT_LT(rel_err(r->estimate.wheelbase, tr.wheelbase), 5e-4);
      EXPECT_EQ(r->fixes_rejected, 0);
      EXPECT_EQ(r->verdict, calib::Verdict::kAccepted);
    }
  }
}

// manual_pass: the factors of one manual UMBmark pass, `odomctl umbmark simulate --noise paper
// --seed S` (5 + 5 squares on the report's floor, 2 mm / 0.4 deg reference).
Factors manual_pass(std::uint64_t seed) {
  analysis::UmbmarkSimOptions uo;
  uo.noise = analysis::UmbmarkNoise::kPaper;
  uo.seed = seed;
  auto manual = analysis::run_umbmark_simulation(uo);
  EXPECT_TRUE(manual) << manual.error().message;
  return manual ? manual->passes[0].result.composed : Factors{1.0, 1.0, kBn};
}

// noisy_seed: 20 excursions with fixes of sigma 5 mm and 0.5 deg on the report's floor
// (roughness up to 1.3 mm every ~2 cm) under the excursions and under every UMBmark square,
// and one manual UMBmark pass (the firmware's simulation at the report's noise: that floor and
// the 2 mm / 0.4 deg reference, 5 + 5 runs). Both E_max,syst are measured by the same 5 + 5
// squares on the same floor. Returns {self-calibrated, manual} [m].
std::pair<double, double> noisy_seed(std::uint64_t seed, bool table) {
  const Factors m = manual_pass(seed);
  const double e_manual = e_max_syst(m, true);
  const Drive d = drive({20, 0.005, 0.5 * kPi / 180.0, true, seed});
  double e = 0.0;
  for (std::size_t n : {5U, 9U, 13U, 17U, 21U}) {
    if (!table && n != 21U) continue;
    auto r = fit(d, config(true), n);
    EXPECT_TRUE(r) << r.error().message;
    e = e_max_syst(r->estimate, true);
    std::printf(
        "seed %llu, %2zu excursions: c_l %.6f c_r %.6f b %.3f mm (sigma %.2g %.2g "
        "%.3f mm) E_max,syst %.2f mm; held-out chi2/dof %.2f vs %.2f in use: %s; "
        "manual pass: b %.3f mm E_max,syst %.2f mm\n",
        static_cast<unsigned long long>(seed), n - 1, r->estimate.c_l, r->estimate.c_r,
        1e3 * r->estimate.wheelbase, r->sigma[0], r->sigma[1], 1e3 * r->sigma[2], 1e3 * e,
        r->score_candidate, r->score_in_use, calib::verdict_name(r->verdict), 1e3 * m.wheelbase,
        1e3 * e_manual);
    if (n != 21U) continue;
    // The rough floor shortens the true travel by about 0.3 % and the dock barely sees the
    // scale, which stays near the prior's 1: the effective b is about 0.337 / 0.997 = 338.0 mm
    // (the manual pass finds 338.2 mm). So b is not compared with the geometric 337 mm here.
    EXPECT_EQ(r->fixes_rejected, 0);
    // A dock drive: the excursions end near the dock, not at it (planned from the noise-free
    // pose, driven on the rough floor), so the fixes see the scale a little (seeds 1-4: 9-33 %
    // of its information); the rest is the prior's.
    EXPECT_LT(r->scale_learnt, 0.5);
    EXPECT_EQ(r->verdict, calib::Verdict::kAccepted);
    EXPECT_LT(r->score_candidate, r->score_in_use);
  }
  return {e, e_manual};
}

TEST(SELFCAL_SUITE, NoisyFixesCalibrateTheLabMate) {
  // What holds on every seed: the candidate after 20 excursions is accepted, and it removes
  // at least 80 % of the nominal robot's E_max,syst (296 mm on this floor).
  const double e_nominal = e_max_syst({1.0, 1.0, kBn}, true);
  std::printf("nominal: E_max,syst %.2f mm\n", 1e3 * e_nominal);
  for (std::uint64_t seed = 1; seed <= 4; ++seed) {
    const auto [e_self, e_manual] = noisy_seed(seed, seed == 1);
    EXPECT_LT(e_self, 0.2 * e_nominal) << "seed " << seed;
  }
}

#if defined(ODO_SELFCAL_STUDY)
double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return 0.5 * (v[(v.size() - 1) / 2] + v[v.size() / 2]);
}

// The yardstick: E_max,syst of the effective truth on the report's floor (c_R/c_L 0.9985, the
// floor shortening every wheel's travel by ~0.32 %: b = 0.337 / (1 - 0.0032) = 338.08 mm at
// scale 1) over independent floor draws. With 5 + 5 squares the centres of gravity keep the
// floor's random error (measured: 12.0 +- 4.7 mm over 40 draws); with 200 + 200 what is left is
// the systematic error (2.1 +- 1.1 mm over 8 draws): every draw below 5 mm.
TEST(SELFCAL_SUITE, TheReportsFiveSquaresMeasureTheFloorMoreThanTheCalibration) {
  const double r = 0.9985, b = 0.337 / (1 - 0.0032);
  const Factors truth{2 / (1 + r), 2 * r / (1 + r), b};
  for (int runs : {5, 200}) {
    const int draws = runs == 5 ? 40 : 8;
    double sum = 0, sum2 = 0, lo = 1e9, hi = 0;
    for (int k = 0; k < draws; ++k) {
      const double e = analysis::selfcal_e_max_syst(truth, true, runs, 200000 + 1000 * k);
      sum += e;
      sum2 += e * e;
      lo = std::min(lo, e);
      hi = std::max(hi, e);
    }
    const double mean = sum / draws, sd = std::sqrt((sum2 - draws * mean * mean) / (draws - 1));
    std::printf("%d + %d squares, %d floor draws: E_max,syst %.2f +- %.2f mm (%.2f .. %.2f)\n",
                runs, runs, draws, 1e3 * mean, 1e3 * sd, 1e3 * lo, 1e3 * hi);
    if (runs == 5) {
      EXPECT_GT(hi, 0.015);  // one perfect calibration scores above 15 mm
    }
    if (runs == 200) {
      EXPECT_LT(hi, 0.005);
    }
  }
}

// Issue 18's target: E_max,syst of the self-calibrated robot (20 excursions, 5 mm / 0.5 deg
// dock fixes, the report's floor) no worse than after one manual UMBmark pass at the report's
// noise, over 24 seeds. Both calibrations are scored by the same squares on the same floor;
// the yardstick is the systematic error the report means, the centres of gravity of 200 cw +
// 200 ccw squares (floor seeds 100000 ..): with the report's 5 + 5 squares the floor's random
// error stays in the centres of gravity and one calibration scores 5 to 18 mm depending on a
// 0.05 mm change of b (BENCHMARKS.md). The 5 + 5 figure is printed too. The manual pass uses
// the floor seeds of `umbmark simulate --seed S`, the excursions seeds S * 1000 + e: the same
// floor statistics, independent draws. Built as study_selfcal (label target). Also printed: the
// mean of 20 floor draws of 5 + 5 squares (floor seeds 300000 + 1000 k), which scores the
// calibration rather than one bump pattern, and the distance scale m = (c_L + c_R) / 2 with its
// reported sigma and b / m (a closed square sees b / m and c_R / c_L, not m).
TEST(SELFCAL_SUITE, NoisyFixesBeatOneManualUmbmarkPass) {
  constexpr int kSeeds = 24, kRuns = 200, kDraws = 20;
  constexpr std::uint64_t kYardstick = 100000, kDrawSeeds = 300000;
  auto mean_of_draws = [](const Factors& f) {
    double sum = 0.0;
    for (int k = 0; k < kDraws; ++k)
      sum += analysis::selfcal_e_max_syst(f, true, 5, kDrawSeeds + 1000 * static_cast<unsigned>(k));
    return sum / kDraws;
  };
  std::vector<double> s5, m5, s_sys, m_sys, s_draws, m_draws;
  for (std::uint64_t seed = 1; seed <= kSeeds; ++seed) {
    const Factors m = manual_pass(seed);
    const Drive d = drive({20, 0.005, 0.5 * kPi / 180.0, true, seed});
    auto r = fit(d, config(true), 21);
    ASSERT_TRUE(r) << r.error().message;
    EXPECT_EQ(r->verdict, calib::Verdict::kAccepted) << "seed " << seed;
    const Factors f = r->estimate;
    s5.push_back(e_max_syst(f, true));
    m5.push_back(e_max_syst(m, true));
    s_sys.push_back(analysis::selfcal_e_max_syst(f, true, kRuns, kYardstick));
    m_sys.push_back(analysis::selfcal_e_max_syst(m, true, kRuns, kYardstick));
    s_draws.push_back(mean_of_draws(f));
    m_draws.push_back(mean_of_draws(m));
    const auto& cv = r->covariance;  // row-major; var(m) = (1/4) sum of the c_L, c_R block
    std::printf(
        "seed %2llu: self m %.6f (sigma %.2g) b/m %.3f mm | 5+5 mean of %d draws: self %5.2f "
        "manual %5.2f mm\n",
        static_cast<unsigned long long>(seed), 0.5 * (f.c_l + f.c_r),
        0.5 * std::sqrt(cv[0] + cv[1] + cv[3] + cv[4]), 2e3 * f.wheelbase / (f.c_l + f.c_r), kDraws,
        1e3 * s_draws.back(), 1e3 * m_draws.back());
    std::printf(
        "seed %2llu: self b %.3f mm c_r/c_l %.6f | manual b %.3f mm c_r/c_l %.6f | E_max,syst "
        "5+5: self %5.2f manual %5.2f mm; 200+200: self %5.2f manual %5.2f mm\n",
        static_cast<unsigned long long>(seed), 1e3 * f.wheelbase, f.c_r / f.c_l, 1e3 * m.wheelbase,
        m.c_r / m.c_l, 1e3 * s5.back(), 1e3 * m5.back(), 1e3 * s_sys.back(), 1e3 * m_sys.back());
  }
  for (std::size_t b = 0; b < kSeeds; b += 8) {
    auto block = [b](const std::vector<double>& v) {
      return 1e3 * median({v.begin() + static_cast<std::ptrdiff_t>(b),
                           v.begin() + static_cast<std::ptrdiff_t>(b + 8)});
    };
    std::printf(
        "seeds %2zu-%2zu: median 5+5 self %.2f manual %.2f; 200+200 self %.2f manual %.2f mm\n",
        b + 1, b + 8, block(s5), block(m5), block(s_sys), block(m_sys));
  }
  std::printf(
      "median over %d seeds: 5+5 self %.2f manual %.2f mm; 200+200 self %.2f manual %.2f mm\n",
      kSeeds, 1e3 * median(s5), 1e3 * median(m5), 1e3 * median(s_sys), 1e3 * median(m_sys));
  std::printf("median over %d seeds of the 5+5 mean of %d floor draws: self %.2f manual %.2f mm\n",
              kSeeds, kDraws, 1e3 * median(s_draws), 1e3 * median(m_draws));
  EXPECT_LE(median(s_sys), median(m_sys));
  // And on the 5 + 5 yardstick once its floor's draw is averaged out.
  EXPECT_LE(median(s_draws), median(m_draws));
}
#endif

TEST(SELFCAL_SUITE, CorruptedFixesAreAllFlagged) {
  // 10 % of the fixes (2 of the 20 after excursions, 3 seeds) moved 0.5-5 m in a random
  // direction, as a wrong landmark match would. Every one must be rejected and no good fix
  // with them; the estimate must be accepted (held-out prediction better than the calibration
  // in use: the store write cannot make it worse) and stay near the clean run's.
  // (20 seeds, 40 corrupted fixes, were run while writing this: 40 flagged, 0 good ones.)
  int corrupted_total = 0, flagged_total = 0;
  for (std::uint64_t seed : {11U, 12U, 13U}) {
    Drive d = drive({20, 0.005, 0.5 * kPi / 180.0, true, seed});
    auto clean = fit(d, config(true), d.fixes.size());
    ASSERT_TRUE(clean) << clean.error().message;
    std::mt19937_64 rng(seed * 77);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    std::set<int> bad;
    while (bad.size() < 2) bad.insert(1 + static_cast<int>(20 * u(rng)) % 20);
    for (int i : bad) {
      const double r = 0.5 + 4.5 * u(rng), a = 2 * kPi * u(rng);
      d.fixes[static_cast<std::size_t>(i)].x += r * std::cos(a);
      d.fixes[static_cast<std::size_t>(i)].y += r * std::sin(a);
    }
    auto res = fit(d, config(true), d.fixes.size());
    ASSERT_TRUE(res) << res.error().message;
    const double e = e_max_syst(res->estimate, true), e_clean = e_max_syst(clean->estimate, true);
    std::printf(
        "seed %llu: corrupted {%d, %d}, rejected %d {%d%s}; b %.3f mm (clean %.3f, sigma "
        "%.3f); E_max,syst %.2f mm (clean %.2f); %s\n",
        static_cast<unsigned long long>(seed), *bad.begin(), *bad.rbegin(), res->fixes_rejected,
        res->rejected.empty() ? -1 : res->rejected.front(), res->rejected.size() > 1 ? ", ..." : "",
        1e3 * res->estimate.wheelbase, 1e3 * clean->estimate.wheelbase, 1e3 * res->sigma[2],
        1e3 * e, 1e3 * e_clean, calib::verdict_name(res->verdict));
    EXPECT_EQ(std::set<int>(res->rejected.begin(), res->rejected.end()), bad);
    corrupted_total += 2;
    flagged_total += res->fixes_rejected;
    EXPECT_EQ(res->verdict, calib::Verdict::kAccepted);
    EXPECT_LT(res->score_candidate, res->score_in_use);
    // Without the two fixes four excursions merge into two and the held-out split moves, so
    // the estimate differs from the clean run's by sampling, within 4 sigma.
    for (int i = 0; i < 3; ++i) {
      const double v[] = {res->estimate.c_l, res->estimate.c_r, res->estimate.wheelbase};
      const double w[] = {clean->estimate.c_l, clean->estimate.c_r, clean->estimate.wheelbase};
      EXPECT_NEAR(v[i], w[i], 4 * res->sigma[static_cast<std::size_t>(i)]) << "parameter " << i;
    }
  }
  std::printf("corrupted %d, flagged %d\n", corrupted_total, flagged_total);
}

}  // namespace
}  // namespace odo
