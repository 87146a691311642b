// Cost of the Chong-Kleeman covariance update per loop tick.
#include <benchmark/benchmark.h>

#include "odo/odometry/error_model.hpp"

namespace {

// One tick of the loop's covariance step: a 1 kHz tick of a gentle arc (series branch).
void BM_CovarianceTick(benchmark::State& state) {
  odo::PoseCovariance pc;
  double theta = 0.3;
  const double l = 0.00050, r = 0.00052;
  for (auto _ : state) {
    benchmark::DoNotOptimize(theta);
    pc.step(theta, l, r, 0.34);
    benchmark::ClobberMemory();
  }
  benchmark::DoNotOptimize(pc.cov());
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_CovarianceTick);

// A tick with a large turn (|phi| > 1 rad: closed-form branch with sin/cos).
void BM_CovarianceTickLargeTurn(benchmark::State& state) {
  odo::PoseCovariance pc;
  double theta = 0.3;
  for (auto _ : state) {
    benchmark::DoNotOptimize(theta);
    pc.step(theta, -0.3, 0.3, 0.34);
    benchmark::ClobberMemory();
  }
  benchmark::DoNotOptimize(pc.cov());
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_CovarianceTickLargeTurn);

}  // namespace
