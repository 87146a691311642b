// Loop benchmarks: one full tick on the simulated backend, and the pose update alone.
#include <benchmark/benchmark.h>

#include <atomic>

#include "odo/loop/loop.hpp"
#include "odo/sim/robot.hpp"
#include "odo/sim/sim_encoder.hpp"
#include "odo/sim/virtual_clock.hpp"

namespace {

odo::KinematicParams labmate() {
  return {0.15, 2048, 16, 0.34, 0.34, 1.0, 1.0};
}

// One loop tick: virtual-clock sleep, simulated encoder read (robot advanced by one period),
// wrap-aware deltas, pose and velocity update, statistics, snapshot publication.
void BM_LoopTick(benchmark::State& state) {
  const auto k = *odo::Kinematics::create(labmate());
  // A long arc so that both wheels count on every tick.
  auto robot = *odo::sim::SimRobot::create(odo::sim::RobotGeometry{}, {{1e7, 3.0, 3.3}});
  odo::sim::SimEncoderSource enc(robot, 32);
  odo::sim::VirtualClock clock;
  auto loop = odo::loop::OdometryLoop::create(odo::loop::LoopConfig{1000.0}, k, enc, clock).value();
  loop->start();
  for (auto _ : state) loop->tick();
  benchmark::DoNotOptimize(loop->odometry().pose());
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_LoopTick);

// The pose update alone: counts of one tick -> pose and velocity.
void BM_PoseUpdate(benchmark::State& state) {
  odo::Odometry odo(*odo::Kinematics::create(labmate()));
  std::int64_t l = 52, r = 57;
  for (auto _ : state) {
    benchmark::DoNotOptimize(l);
    benchmark::DoNotOptimize(r);
    odo.update(l, r, 0.001);
    benchmark::ClobberMemory();
  }
  benchmark::DoNotOptimize(odo.pose());
}
BENCHMARK(BM_PoseUpdate);

}  // namespace
