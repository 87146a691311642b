// [gyro] backend = "can" on the simulated robot (issue 16's CAN gyro backend): sim_hal's CAN IMU
// sends the simulated gyro's samples as frames, the firmware's real decoder (drivers/can_gyro)
// reads them, and the loop fuses them as it fuses the simulated gyro read directly.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <memory>

#include "odo/firmware/config.hpp"
#include "odo/firmware/rig.hpp"
#include "odo/loop/loop.hpp"
#include "odo/sim/sim_can_imu.hpp"

namespace odo::test {
namespace {

// run: `ticks` ticks of the loop on `cfg`'s rig in virtual time; the final snapshot.
loop::LoopSnapshot run(const fw::Config& cfg, std::uint64_t ticks) {
  auto kin = Kinematics::create(cfg.robot).value();
  auto rig = fw::Rig::create(cfg, kin, /*virtual_time=*/true);
  EXPECT_TRUE(rig.ok()) << rig.error().message;
  if (!rig.ok()) return {};
  loop::LoopConfig lc;
  lc.rate_hz = cfg.loop.rate_hz;
  lc.gyrodometry = rig->gyrodometry();
  auto loop = loop::OdometryLoop::create(lc, kin, rig->encoder(), rig->clock(), rig->gyro());
  EXPECT_TRUE(loop.ok()) << loop.error().message;
  if (!loop.ok()) return {};
  (*loop)->start();
  for (std::uint64_t i = 0; i < ticks; ++i) (*loop)->tick();
  return (*loop)->snapshot();
}

// The squares at 1 kHz with the wheel acceleration limit below what their ramps need: every
// start and stop of a leg opens a flagged interval, so the gyro's rate is integrated into the
// pose, not only compared.
fw::Config squares(fw::GyroBackend backend) {
  fw::Config cfg = fw::default_config();
  cfg.loop.rate_hz = 1000.0;
  cfg.sim.scenario = fw::SimScenario::kSquares;
  cfg.gyro.backend = backend;
  cfg.gyro.max_wheel_accel = 0.05;
  cfg.can_gyro.bus = fw::CanEncoderBus::kSim;
  return cfg;
}

TEST(RigCanGyro, SameFusionAsTheSimulatedGyroReadDirectly) {
  // The CAN field's LSB is the simulated gyro's own (2000 deg/s over 2^15), so packing its
  // already quantised samples loses nothing; mounted upside down (sign -1), the chip sends the
  // negated rate and the decoder negates it back, both exactly. Big endian, 29-bit id, at byte 2:
  // the decoder must find the field where the chip put it. So the two runs must agree bit for
  // bit: same samples, same flagged intervals, same pose.
  const fw::Config direct = squares(fw::GyroBackend::kSim);
  fw::Config can = squares(fw::GyroBackend::kCan);
  can.gyro.sign = -1;
  can.can_gyro.extended = true;
  can.can_gyro.id = 0x18FF1234;
  can.can_gyro.offset = 2;
  can.can_gyro.byte_order = fw::ByteOrder::kBig;
  constexpr std::uint64_t kTicks = 60'000;
  const loop::LoopSnapshot a = run(direct, kTicks), b = run(can, kTicks);
  ASSERT_TRUE(a.gyro.enabled);
  ASSERT_TRUE(b.gyro.enabled);
  EXPECT_GT(b.gyro.gyro.samples, kTicks - 10);  // a 1 kHz gyro read at 1 kHz
  EXPECT_EQ(b.gyro.gyro.samples, a.gyro.gyro.samples);
  EXPECT_GT(b.gyro.fusion.gyro_used_ticks, 0u);
  EXPECT_EQ(b.gyro.fusion.gyro_used_ticks, a.gyro.fusion.gyro_used_ticks);
  EXPECT_EQ(b.gyro.fusion.accel_events, a.gyro.fusion.accel_events);
  EXPECT_EQ(b.gyro.bias, a.gyro.bias);
  EXPECT_EQ(b.pose.x, a.pose.x);
  EXPECT_EQ(b.pose.y, a.pose.y);
  EXPECT_EQ(b.pose.theta, a.pose.theta);
  EXPECT_EQ(b.cov, a.cov);
  EXPECT_EQ(b.gyro.gyro.stale_events, 0u);
}

TEST(RigCanGyro, ImuThatStopsSendingIsStaleAndTheFusionFallsBack) {
  // The IMU stops at robot time 5 s; [gyro] stale_timeout 0.05 s: from 5.05 s on every tick is
  // flagged stale, once counted as an event, and the fusion integrates odometry alone. The
  // fusion counts transitions into a fault: one, the stop (the first tick, before the IMU's first
  // sample after its 2 ms delay, is kGyroStarting: neither a stale event nor a fault).
  // Odometry alone from then on: the pose still moves with the wheels and stays finite.
  fw::Config cfg = squares(fw::GyroBackend::kCan);
  cfg.can_gyro.sim_stop_after = 5.0;
  const loop::LoopSnapshot s = run(cfg, 20'000);
  EXPECT_NE(s.gyro.gyro_flags & kGyroStale, 0u);
  EXPECT_EQ(s.gyro.gyro.stale_events, 1u);
  EXPECT_EQ(s.gyro.fusion.gyro_faults, 1u);
  EXPECT_NE(s.gyro.fusion_flags & kFusionGyroFault, 0u);
  EXPECT_LE(s.gyro.gyro.samples, 5'000u);  // none after 5 s (the first one at 2 ms)
  EXPECT_GT(s.gyro.gyro.samples, 4'990u);
  EXPECT_TRUE(std::isfinite(s.pose.x) && std::isfinite(s.pose.y) && std::isfinite(s.pose.theta));
  EXPECT_GT(s.distance, 1.0);
}

// packed: the data bytes SimCanImu sends for `rate` [rad/s] with options `o`.
std::array<std::uint8_t, 8> packed(const sim::SimCanImuOptions& o, double rate) {
  sim::SimRobot robot =
      sim::SimRobot::create(sim::RobotGeometry{}, sim::Scenario{{1.0, 0.0, 0.0}}).value();
  sim::SimCanImu imu(sim::SimGyro::create(robot, sim::consumer_gyro(), 1).value(), robot, o);
  CanFrame f;
  imu.pack(rate, f);
  EXPECT_EQ(f.len, 8);
  return f.data;
}

TEST(SimCanImu, PacksTheRateAsTheDataSheetLayoutSays) {
  sim::SimCanImuOptions o;
  o.scale = 1e-3;  // 1 mrad/s per LSB
  // 0.5 rad/s = 500 LSB = 0x01F4, little endian at byte 0: F4 01.
  EXPECT_EQ(packed(o, 0.5), (std::array<std::uint8_t, 8>{0xF4, 0x01}));
  // 0.0004 rad/s is 0.4 LSB: rounded to 0; -0.0016 is -1.6 LSB: -2 = 0xFFFE.
  EXPECT_EQ(packed(o, 0.0004), (std::array<std::uint8_t, 8>{}));
  EXPECT_EQ(packed(o, -0.0016), (std::array<std::uint8_t, 8>{0xFE, 0xFF}));
  // Beyond the range the chip holds the ends: 40 rad/s -> 32767 = 0x7FFF, -40 -> -32768 = 0x8000.
  EXPECT_EQ(packed(o, 40.0), (std::array<std::uint8_t, 8>{0xFF, 0x7F}));
  EXPECT_EQ(packed(o, -40.0), (std::array<std::uint8_t, 8>{0x00, 0x80}));
  // 24-bit big endian at byte 3: -1 rad/s = -1000 LSB = 0xFFFC18, most significant byte first.
  o.width_bits = 24;
  o.big_endian = true;
  o.byte_offset = 3;
  EXPECT_EQ(packed(o, -1.0), (std::array<std::uint8_t, 8>{0, 0, 0, 0xFF, 0xFC, 0x18}));
  // Unsigned 16-bit with offset -32.768 rad/s (J1939 style): 0 rad/s is 32768 = 0x8000,
  // 1 rad/s is 33768 = 0x83E8; little endian at byte 1.
  o = sim::SimCanImuOptions{};
  o.scale = 1e-3;
  o.is_signed = false;
  o.offset = -32.768;
  o.byte_offset = 1;
  EXPECT_EQ(packed(o, 0.0), (std::array<std::uint8_t, 8>{0, 0x00, 0x80}));
  EXPECT_EQ(packed(o, 1.0), (std::array<std::uint8_t, 8>{0, 0xE8, 0x83}));
}

}  // namespace
}  // namespace odo::test
