// The quadrature decode table (GPIO backend) and the CAN pose frame encoding (broadcaster), each
// alone.
#include <benchmark/benchmark.h>

#include <array>
#include <cstdint>

#include "odo/drivers/quad_tracker.hpp"
#include "odo/protocol/can_protocol.hpp"
#include "odo/hal/can_bus.hpp"
#include "odo/hal/quadrature.hpp"

namespace {

// The 4x table alone: one forward transition per iteration through the Gray sequence.
void BM_QuadDecodeTable(benchmark::State& state) {
  std::int64_t count = 0;
  odo::QuadState s = odo::quad_state_at(0);
  for (auto _ : state) {
    const odo::QuadState next = odo::quad_state_at(count + 1);
    count += odo::quad_delta(odo::quad_decode(s, next));
    s = next;
    benchmark::DoNotOptimize(count);
  }
}
BENCHMARK(BM_QuadDecodeTable);

// One edge event through the GPIO decoder's tracker (line mask, levels, table, invalid check).
void BM_QuadTrackerEdge(benchmark::State& state) {
  // Forward motion alternates A and B edges: 00 -> A=1 -> B=1 -> A=0 -> B=0.
  constexpr std::array<std::uint8_t, 4> kMask{2, 1, 2, 1};
  constexpr std::array<std::uint8_t, 4> kLevels{2, 3, 1, 0};
  odo::drivers::QuadTracker t;
  std::size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(t.apply(kMask[i & 3u], kLevels[i & 3u]));
    ++i;
  }
  if (t.count() != static_cast<std::int64_t>(i)) state.SkipWithError("tracker lost counts");
}
BENCHMARK(BM_QuadTrackerEdge);

// The pose group of one tick: PoseX + PoseYTheta (the two frames sent together).
void BM_CanEncodePoseGroup(benchmark::State& state) {
  odo::protocol::PoseMsg p{1234.5678, -87.6543, 7.25, 0};
  odo::CanFrame a, b;
  for (auto _ : state) {
    ++p.seq;
    odo::protocol::encode_pose_x(0x410, p, a);
    odo::protocol::encode_pose_y_theta(0x411, p, b);
    benchmark::DoNotOptimize(a);
    benchmark::DoNotOptimize(b);
  }
}
BENCHMARK(BM_CanEncodePoseGroup);

// Every broadcast frame of one tick: pose group, velocity, uncertainty, status, timing.
void BM_CanEncodeAllFrames(benchmark::State& state) {
  odo::protocol::PoseMsg p{1234.5678, -87.6543, 7.25, 0};
  const odo::protocol::VelocityMsg v{0.2, -0.1, 0};
  const odo::protocol::UncertaintyMsg u{0.012, 0.034, 0.0021, 0.3, 0};
  const odo::protocol::StatusMsg s{0, 1, false, 3, 12, 3600.0};
  const odo::protocol::TimingMsg t{25e-6, 80e-6, 4e-6, 0};
  std::array<odo::CanFrame, 6> f;
  for (auto _ : state) {
    ++p.seq;
    odo::protocol::encode_pose_x(0x410, p, f[0]);
    odo::protocol::encode_pose_y_theta(0x411, p, f[1]);
    odo::protocol::encode_velocity(0x412, v, f[2]);
    odo::protocol::encode_uncertainty(0x413, u, f[3]);
    odo::protocol::encode_status(0x414, s, f[4]);
    odo::protocol::encode_timing(0x415, t, f[5]);
    benchmark::DoNotOptimize(f);
  }
}
BENCHMARK(BM_CanEncodeAllFrames);

}  // namespace
