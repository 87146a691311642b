// gyro_tick_driver: instructions per tick of the gyro path for callgrind, before the fusion is
// in the loop (issue 16): SimGyro::read (consumer model, 1 kHz output) and Gyrodometry::step at a
// 1 kHz tick on a long, slightly curved run (the window compared every tick, no interval).
// Usage: gyro_tick_driver N; then
//   valgrind --tool=callgrind --callgrind-out-file=g.out build/bench/tests/bench/gyro_tick_driver
//   100000 && callgrind_annotate --inclusive=yes g.out | grep -E 'fuse|gyro_read'
// and divide by N.
#include <cstdio>
#include <cstdlib>

#include "odo/odometry/gyrodometry.hpp"
#include "odo/sim/robot.hpp"
#include "odo/sim/sim_gyro.hpp"

namespace {

__attribute__((noinline)) odo::FusedTick fuse(odo::Gyrodometry& g, const odo::FusionInput& in) {
  return g.step(in);
}

__attribute__((noinline)) odo::GyroSample gyro_read(odo::sim::SimGyro& g, odo::TimeNs t) {
  return g.read(t);
}

}  // namespace

int main(int argc, char** argv) {
  const long n = argc == 2 ? std::atol(argv[1]) : 0;
  if (n <= 0) {
    std::fprintf(stderr, "usage: gyro_tick_driver N (ticks, > 0)\n");
    return 2;
  }
  const odo::sim::RobotGeometry geo;
  const double w = 0.2 / 0.075;
  auto robot =
      odo::sim::SimRobot::create(geo, odo::sim::Scenario{{2.0, 0, 0}, {1e6, w, w * 1.01}}).value();
  auto gyro = odo::sim::SimGyro::create(robot, odo::sim::consumer_gyro(), 1).value();
  odo::GyrodometryParams p;
  p.tick = 0.001;
  p.heading_quantum = 8.46e-5;
  auto fusion = odo::Gyrodometry::create(p).value();
  double heading = 0.0;
  long used = 0;
  for (long i = 1; i <= n; ++i) {
    const odo::TimeNs t = odo::TimeNs{i} * 1'000'000;
    robot.advance_to(t);
    odo::FusionInput in;
    in.dt = 0.001;
    in.wheelbase = 0.34;
    in.d_left = i > 2000 ? 0.0002 : 0.0;  // moving after 2 s of standstill (bias estimate)
    in.d_right = i > 2000 ? 0.000202 : 0.0;
    in.gyro = gyro_read(gyro, t);
    const odo::FusedTick f = fuse(fusion, in);
    heading += f.dtheta;
    used += (f.flags & odo::kFusionGyroUsed) != 0;
  }
  std::printf("heading %g rad, %ld gyro ticks\n", heading, used);
  return 0;
}
