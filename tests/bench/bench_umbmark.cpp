// Cost of the UMBmark calculation (calibration/umbmark) and of one simulated self-calibration.
#include <benchmark/benchmark.h>

#include <vector>

#include "odo/analysis/umbmark_tools.hpp"
#include "odo/calibration/umbmark.hpp"

namespace {

// umbmark_compute on n cw + n ccw runs spread around the LabMate's centres of gravity.
void BM_UmbmarkCompute(benchmark::State& state) {
  odo::calib::UmbmarkInput in;
  const auto n = static_cast<int>(state.range(0));
  for (int i = 0; i < n; ++i) {
    const double d = 1e-3 * (i % 7 - 3);
    in.runs.push_back({odo::calib::Direction::kCw, -0.05 + d, -0.35 - d, std::nullopt, false});
    in.runs.push_back({odo::calib::Direction::kCcw, -0.16 - d, 0.20 + d, std::nullopt, false});
  }
  in.current = {1.0, 1.0, 0.34};
  for (auto _ : state) {
    auto r = odo::calib::umbmark_compute(in);
    benchmark::DoNotOptimize(r);
  }
  state.SetItemsProcessed(state.iterations() * 2 * n);
}
BENCHMARK(BM_UmbmarkCompute)->Arg(5)->Arg(1000);

// One whole simulated pass with N = 1: 2 squares before and 2 after, 4 m sides, virtual time,
// each through the firmware's odo::loop::OdometryLoop at 100 Hz (about 9 700 ticks a square).
void BM_UmbmarkSimulatePass(benchmark::State& state) {
  odo::analysis::UmbmarkSimOptions o;
  o.runs = 1;
  o.noise = state.range(0) != 0 ? "paper" : "none";
  for (auto _ : state) {
    auto r = odo::analysis::run_umbmark_simulation(o);
    benchmark::DoNotOptimize(r);
  }
  state.SetItemsProcessed(state.iterations() * 4);  // squares
}
BENCHMARK(BM_UmbmarkSimulatePass)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

}  // namespace
