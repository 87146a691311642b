// Cost of self-calibration from absolute fixes (issue 18): the loop's per-tick recording
// (CountRecorder::add_tick) and the off-loop fit (fit_fixes) per fix.
#include <benchmark/benchmark.h>

#include <random>
#include <vector>

#include "odo/calibration/count_recorder.hpp"
#include "odo/calibration/selfcal.hpp"

namespace {

using odo::calib::LegCounts;

// A LabMate-like excursion as the recorder cuts it: 3300 segments of 20 ms (the sim's 20
// excursions gave 66 585 segments), straights, arcs and spins at 0.2 m/s (278 counts per wheel
// per segment at c_m = 14.4 um), with fixes of 5 mm / 0.5 deg at both ends.
odo::calib::FixTrack make_track(int excursions) {
  constexpr double kCm = 1.4381e-5;
  const odo::calib::Factors truth{1.00075, 0.99925, 0.337};
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::normal_distribution<double> n01;
  odo::calib::FixTrack t;
  odo::Pose2 q;
  t.fixes.push_back({0, 0.0, 0.0, 0.0, 0.005, 0.0087});
  for (int e = 0; e < excursions; ++e) {
    std::vector<LegCounts> leg;
    for (int piece = 0; piece < 6; ++piece) {
      const double a = u(rng), b = u(rng);
      const double nl = piece % 3 == 2 ? -139.0 * b : 278.0 * (1.0 + 0.2 * a);
      const double nr = piece % 3 == 2 ? 139.0 * b : 278.0 * (1.0 - 0.2 * a);
      for (int s = 0; s < 550; ++s) leg.push_back({nl, nr});
    }
    q = odo::calib::predict_excursion(q, leg, truth, kCm);
    t.fixes.push_back({(e + 1) * odo::kNsPerSecond, q.x + 0.005 * n01(rng), q.y + 0.005 * n01(rng),
                       odo::wrap_angle(q.theta + 0.0087 * n01(rng)), 0.005, 0.0087});
    t.legs.push_back(std::move(leg));
  }
  return t;
}

// fit_fixes over N excursions (the whole pipeline: rejection, re-check, the acceptance folds);
// items are fixes, so items/s is the inverse of the cost per fix. BM_FitFixes: the default
// cross-validated acceptance (four folds' fits and the fit on all); BM_FitFixesHoldOut: one
// fold held out, as before.
void fit_fixes_bench(benchmark::State& state, odo::calib::Acceptance a) {
  const auto n = static_cast<int>(state.range(0));
  const odo::calib::FixTrack t = make_track(n);
  odo::calib::SelfCalConfig c;
  c.metres_per_count = 1.4381e-5;
  c.in_use = {1.0, 1.0, 0.34};
  c.acceptance = a;
  for (auto _ : state) {
    auto r = odo::calib::fit_fixes(t, c);
    benchmark::DoNotOptimize(r);
  }
  state.SetItemsProcessed(state.iterations() * n);
}
void BM_FitFixes(benchmark::State& state) {
  fit_fixes_bench(state, odo::calib::Acceptance::kCrossValidated);
}
void BM_FitFixesHoldOut(benchmark::State& state) {
  fit_fixes_bench(state, odo::calib::Acceptance::kHoldOut);
}
BENCHMARK(BM_FitFixes)->Arg(5)->Arg(20)->Arg(40)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_FitFixesHoldOut)->Arg(20)->Unit(benchmark::kMillisecond);

// One tick of the loop's recording: add_tick with LabMate counts at 100 Hz (a segment closes
// every second tick).
void BM_RecorderTick(benchmark::State& state) {
  odo::calib::CountRecorder rec(odo::calib::RecorderLimits{23, 6953, 20'000'000});
  rec.start(0);
  odo::calib::CountSegment seg;
  odo::TimeNs t = 0;
  std::int64_t closed = 0;
  for (auto _ : state) {
    t += 10'000'000;
    closed += rec.add_tick(t, 139, 139 + (t / 10'000'000) % 2, seg) ? 1 : 0;
    benchmark::DoNotOptimize(seg);
  }
  benchmark::DoNotOptimize(closed);
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_RecorderTick);

}  // namespace
