// tick_driver: runs N loop ticks for instruction counting with callgrind
// (tools/callgrind_tick.sh). Usage: tick_driver sim|counting|gyro|fwgyro N [all|persist|record]
//   sim       the simulated robot on a long arc (as BM_LoopTick)
//   counting  a counter-register encoder (as BM_LoopTickFirmwareOnly)
//   gyro      sim with the consumer gyro (1 kHz samples) and the fusion in the loop; the robot
//             stands still for the first second, so the bias is learnt and every later tick
//             compares its window (the fusion's full path, no interval)
//   fwgyro    counting with a gyro read from memory (CountingGyro) and the same fusion, also
//             still for the first second: the firmware's own cost of a tick with the gyro
// The CAN broadcaster is attached as in odometryd with the simulated bus: default rates at
// 1 kHz (pose and velocity every 20th tick, uncertainty and status every 100th, timing every
// 1000th), the wire drained every tick; `all` sends every message on every tick (worst case).
// `persist` also attaches the state persister as odometryd does (issue 17: a record every 20th
// tick at the default 50 Hz, written by its own thread into a file under /tmp). `record` reads
// the encoder through the self-calibration recorder as odometryd does with [selfcal] enabled
// (issue 18: count segments into the estimator's ring; the estimator itself runs elsewhere).
#include <unistd.h>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <iostream>
#include <memory>
#include <optional>
#include <string>

#include "counting_encoder.hpp"
#include "counting_gyro.hpp"
#include "odo/firmware/can_broadcast.hpp"
#include "odo/firmware/state_persist.hpp"
#include "odo/loop/loop.hpp"
#include "odo/loop/recording_encoder.hpp"
#include "odo/sim/robot.hpp"
#include "odo/sim/sim_can_bus.hpp"
#include "odo/sim/sim_encoder.hpp"
#include "odo/sim/sim_gyro.hpp"
#include "odo/sim/virtual_clock.hpp"

namespace {

// Args: the command line, checked; nullopt after a usage message.
struct Args {
  char mode;  // 's'im, 'c'ounting, 'g'yro, 'f'wgyro
  long n;
  bool all, persist, record;
};

std::optional<Args> parse(int argc, char** argv) {
  const char* opt = argc == 4 ? argv[3] : "";
  Args a{argc >= 2 ? argv[1][0] : '?', argc >= 3 ? std::atol(argv[2]) : 0,
         std::strcmp(opt, "all") == 0, std::strcmp(opt, "persist") == 0,
         std::strcmp(opt, "record") == 0};
  if (argc < 3 || argc > 4 || (argc == 4 && !a.all && !a.persist && !a.record) ||
      (std::strcmp(argv[1], "sim") != 0 && std::strcmp(argv[1], "counting") != 0 &&
       std::strcmp(argv[1], "gyro") != 0 && std::strcmp(argv[1], "fwgyro") != 0)) {
    std::fprintf(stderr, "usage: tick_driver sim|counting|gyro|fwgyro N [all|persist|record]\n");
    return std::nullopt;
  }
  if (a.n <= 0) {
    std::fprintf(stderr, "tick_driver: N = '%s' must be a positive integer\n", argv[2]);
    return std::nullopt;
  }
  return a;
}

// attach_persister: the state persister on `loop` as odometryd attaches it; null on error.
std::unique_ptr<odo::fw::StatePersister> attach_persister(odo::loop::OdometryLoop& loop,
                                                          const std::string& path) {
  auto p = odo::fw::StatePersister::create(path, 50.0, 1000.0, loop, {});
  if (!p) {
    std::fprintf(stderr, "tick_driver: %s\n", p.error().message.c_str());
    return nullptr;
  }
  loop.add_observer(p->get());
  return std::move(p).value();
}

}  // namespace

int main(int argc, char** argv) {
  const std::optional<Args> args = parse(argc, argv);
  if (!args) return 2;
  const auto [mode, n, all, persist, record] = *args;
  const auto k = *odo::Kinematics::create({0.15, 2048, 16, 0.34, 0.34, 1.0, 1.0});
  const bool with_gyro = mode == 'g' || mode == 'f';
  odo::sim::Scenario path{{1e7, 3.0, 3.3}};
  if (with_gyro) path.insert(path.begin(), {1.0, 0.0, 0.0});
  auto robot = *odo::sim::SimRobot::create(odo::sim::RobotGeometry{}, path);
  odo::sim::SimEncoderSource sim_enc(robot, 32);
  const bool counting = mode == 'c' || mode == 'f';
  // fwgyro: still for the first 1000 reads (the driver sets the steps then, outside the ticks).
  odo::bench::CountingEncoder count_enc(mode == 'f' ? 0 : 52, mode == 'f' ? 0 : 57);
  odo::EncoderSource& raw = counting ? static_cast<odo::EncoderSource&>(count_enc)
                                     : static_cast<odo::EncoderSource&>(sim_enc);
  odo::loop::SegmentRing segments(8192);  // 20 s at 1 kHz close ~1000 segments: never full
  odo::loop::RecordingEncoder recorder(raw, *odo::calib::recorder_limits(k), segments);
  odo::EncoderSource& enc = record ? static_cast<odo::EncoderSource&>(recorder) : raw;
  odo::sim::VirtualClock clock;
  const odo::sim::GyroModel model = odo::sim::consumer_gyro();
  auto sim_gyro = *odo::sim::SimGyro::create(robot, model, 1);
  // The counting encoder's arc rate, the first 1 s still and the model's 2 ms output delay.
  const double arc_rate =
      (57.0 * k.metres_per_count_right() - 52.0 * k.metres_per_count_left()) / k.wheelbase() * 1e3;
  odo::bench::CountingGyro count_gyro(1002, arc_rate);
  odo::YawRateSource* gyro = !with_gyro ? nullptr
                             : counting ? static_cast<odo::YawRateSource*>(&count_gyro)
                                        : static_cast<odo::YawRateSource*>(&sim_gyro);
  odo::loop::LoopConfig cfg{1000.0};
  // As odometryd sets them for [gyro] backend = "sim" (firmware/src/gyro_backend.cpp).
  cfg.gyrodometry.noise.rate_noise_density = model.noise_density;
  cfg.gyrodometry.noise.bias_instability = model.bias_walk * 10.0;
  cfg.gyrodometry.gyro_delay = model.delay;
  auto loop = odo::loop::OdometryLoop::create(cfg, k, enc, clock, gyro).value();
  odo::sim::SimCanPort port;
  odo::fw::CanBroadcastOptions co;
  co.div = all ? odo::fw::CanDivisors{1, 1, 1, 1, 1} : odo::fw::CanDivisors{20, 20, 100, 100, 1000};
  port.connect_wire();
  odo::fw::CanBroadcaster can(co, port, &loop->commands(), nullptr);
  loop->add_observer(&can);
  std::unique_ptr<odo::fw::StatePersister> persister;
  const std::string state_path = "/tmp/tick_driver_state." + std::to_string(getpid());
  if (persist && !(persister = attach_persister(*loop, state_path))) return 1;
  loop->start();
  if (persister) persister->start(std::cerr, std::nullopt, "");
  for (long i = 0; i < n; ++i) {
    if (mode == 'f' && i == 1000) count_enc.set_steps(52, 57);
    loop->tick();
  }
  if (persister) {
    persister->stop();
    std::printf("state records written=%llu\n",
                static_cast<unsigned long long>(persister->written()));
    std::remove(state_path.c_str());
  }
  if (record) {
    unsigned long long closed = 0;
    for (odo::calib::CountSegment seg; segments.pop(seg);) ++closed;
    std::printf("segments recorded=%llu\n", closed);
  }
  const odo::Pose2& p = loop->odometry().pose();
  const odo::Gyrodometry* f = loop->fusion();
  std::printf(
      "ticks=%llu x=%.6f y=%.6f theta=%.6f can_sent=%llu fusion_events=%llu bias_valid=%d\n",
      static_cast<unsigned long long>(loop->stats().ticks), p.x, p.y, p.theta,
      static_cast<unsigned long long>(can.counters().sent),
      static_cast<unsigned long long>(f ? f->counters().disagreements : 0),
      f ? int(f->bias_valid()) : 0);
  return 0;
}
