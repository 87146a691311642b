// Each stage of a loop tick alone, and the tick without the simulated robot.
#include <benchmark/benchmark.h>

#include <cstdint>

#include "counting_encoder.hpp"
#include "odo/loop/latency_histogram.hpp"
#include "odo/loop/loop.hpp"
#include "odo/loop/triple_buffer.hpp"
#include "odo/odometry/count_delta.hpp"
#include "odo/sim/robot.hpp"
#include "odo/sim/sim_encoder.hpp"
#include "odo/sim/virtual_clock.hpp"

namespace {

odo::KinematicParams labmate() {
  return {0.15, 2048, 16, 0.34, 0.34, 1.0, 1.0};
}

// One full tick with a counter-register encoder instead of the simulated robot: sleep on the
// virtual clock, read, deltas, pose + velocity, statistics (histograms), snapshot publication.
void BM_LoopTickFirmwareOnly(benchmark::State& state) {
  const auto k = *odo::Kinematics::create(labmate());
  odo::bench::CountingEncoder enc(52, 57);
  odo::sim::VirtualClock clock;
  auto loop = odo::loop::OdometryLoop::create(odo::loop::LoopConfig{1000.0}, k, enc, clock).value();
  loop->start();
  for (auto _ : state) loop->tick();
  benchmark::DoNotOptimize(loop->odometry().pose());
}
BENCHMARK(BM_LoopTickFirmwareOnly);

// Stage: the simulated encoder read (robot advanced by 1 ms on a long arc, counters latched).
void BM_StageSimEncoderRead(benchmark::State& state) {
  auto robot = *odo::sim::SimRobot::create(odo::sim::RobotGeometry{}, {{1e7, 3.0, 3.3}});
  odo::sim::SimEncoderSource enc(robot, 32);
  odo::TimeNs t = 0;
  for (auto _ : state) {
    t += 1'000'000;
    benchmark::DoNotOptimize(enc.read(t));
  }
}
BENCHMARK(BM_StageSimEncoderRead);

// Stage: wrap-aware deltas of both 16-bit counters.
void BM_StageWrapDelta(benchmark::State& state) {
  std::int64_t prev_l = 65500, prev_r = 65530, l = 20, r = 60;
  for (auto _ : state) {
    benchmark::DoNotOptimize(prev_l);
    benchmark::DoNotOptimize(l);
    benchmark::DoNotOptimize(odo::wrap_delta(prev_l, l, 16));
    benchmark::DoNotOptimize(odo::wrap_delta(prev_r, r, 16));
  }
}
BENCHMARK(BM_StageWrapDelta);

// Stage: statistics: one wake-up latency and one compute time into their histograms.
void BM_StageHistogramRecord(benchmark::State& state) {
  odo::loop::LatencyHistogram lat, cmp;
  odo::TimeNs v = 12'345;
  for (auto _ : state) {
    benchmark::DoNotOptimize(v);
    lat.record(v);
    cmp.record(v >> 3);
    v = (v * 5 + 17) & 0xFFFFF;  // spread over the buckets
  }
  benchmark::DoNotOptimize(lat.count());
}
BENCHMARK(BM_StageHistogramRecord);

// Stage (every 256th tick): min, mean, p99, p99.9, max of a histogram of 10^5 latencies.
void BM_StageHistogramSummary(benchmark::State& state) {
  odo::loop::LatencyHistogram h;
  odo::TimeNs v = 1;
  for (int i = 0; i < 100'000; ++i) {
    h.record(10'000 + (v % 40'000));
    v = v * 6364136223846793005LL + 1442695040888963407LL;
    if (v < 0) v = -v;
  }
  for (auto _ : state) benchmark::DoNotOptimize(h.summary());
}
BENCHMARK(BM_StageHistogramSummary);

// Stage: publishing the tick's snapshot to the status thread (triple buffer, wait-free). The
// loop fills the back slot in place, so publishing is the hand-over alone.
void BM_StageSnapshotPublish(benchmark::State& state) {
  odo::loop::TripleBuffer<odo::loop::LoopSnapshot> tb;
  std::uint64_t tick = 0;
  for (auto _ : state) {
    tb.back().tick = ++tick;
    tb.publish();
    benchmark::ClobberMemory();
  }
}
BENCHMARK(BM_StageSnapshotPublish);

}  // namespace
