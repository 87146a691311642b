// The daemon's side of the pose that survives restarts (issue 17): boot id, state file, the
// [resume] config section and which backends may resume.
#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>

#include "odo/firmware/config.hpp"
#include "odo/firmware/state_persist.hpp"

namespace odo::fw {
namespace {

TEST(StatePersist, BootIdParsesTheKernelsText) {
  auto id = parse_boot_id("0123abcd-4567-89ab-cdef-0011223344ff\n");
  ASSERT_TRUE(id) << id.error().message;
  EXPECT_EQ((*id)[0], 0x01);
  EXPECT_EQ((*id)[3], 0xcd);
  EXPECT_EQ((*id)[15], 0xff);
  EXPECT_FALSE(parse_boot_id("0123abcd-4567"));
  EXPECT_FALSE(parse_boot_id("0123abcd-4567-89ab-cdef-0011223344fg"));
  EXPECT_FALSE(parse_boot_id("0123abcd-4567-89ab-cdef-0011223344ff00"));
}

TEST(StatePersist, BootIdFromTheEnvironmentWhereProcSysIsHidden) {
  const std::string hidden = ::testing::TempDir() + "no_such_dir/boot_id";
  const std::string state = ::testing::TempDir() + "state.bin";
  // The kernel's file wins when readable.
  const std::string file = ::testing::TempDir() + "boot_id_test";
  std::ofstream(file) << "00000000-0000-0000-0000-0000000000aa\n";
  auto id = current_boot_id(state, "0123abcd456789abcdef0011223344ff", file);
  ASSERT_TRUE(id) << id.error().message;
  EXPECT_EQ((*id)[15], 0xaa);
  // Hidden: systemd's %b (32 hex digits, no dashes) from ODOMETRYD_BOOT_ID.
  id = current_boot_id(state, "0123abcd456789abcdef0011223344ff", hidden);
  ASSERT_TRUE(id) << id.error().message;
  EXPECT_EQ((*id)[0], 0x01);
  EXPECT_EQ((*id)[15], 0xff);
  // A value that is no boot id is an error naming the variable and the value, never "this boot".
  id = current_boot_id(state, "%b", hidden);
  ASSERT_FALSE(id);
  EXPECT_NE(id.error().message.find("ODOMETRYD_BOOT_ID=\"%b\""), std::string::npos)
      << id.error().message;
}

TEST(StatePersist, OnlyCountersThatKeepCountingResume) {
  Config c = default_config();
  c.encoder.backend = EncoderKind::kGpio;  // decoded by this process: lost while it is down
  EXPECT_FALSE(counters_survive_restart(c));
  c.encoder.backend = EncoderKind::kSim;
  EXPECT_FALSE(counters_survive_restart(c));
  c.encoder.backend = EncoderKind::kHctl1100;
  c.hctl1100.bus = HctlBus::kSim;  // the register model restarts with the process
  EXPECT_FALSE(counters_survive_restart(c));
  c.hctl1100.bus = HctlBus::kGpio;  // the chips count on their own
  EXPECT_TRUE(counters_survive_restart(c));
  c.encoder.backend = EncoderKind::kCan;
  c.can_encoder.bus = CanEncoderBus::kSim;  // the simulated ODrives restart with the process
  EXPECT_FALSE(counters_survive_restart(c));
  c.can_encoder.bus = CanEncoderBus::kSocketCan;  // the controllers' own counters
  EXPECT_TRUE(counters_survive_restart(c));
  // Two wheels per side: the sides' counts are this process's combination, from 0 at its start.
  c.encoder.side.wheels_per_side = 2;
  EXPECT_FALSE(counters_survive_restart(c));
  c.encoder.backend = EncoderKind::kSerial;
  c.serial.link = SerialLink::kTty;
  EXPECT_FALSE(counters_survive_restart(c));
  c.encoder.side.wheels_per_side = 1;
  EXPECT_TRUE(counters_survive_restart(c));
}

// A learnt bias belongs to one gyro: whatever changes the meaning of its rate makes another id;
// the fusion's own settings (noise figures, thresholds) do not.
TEST(StatePersist, GyroIdNamesTheGyroNotTheFusion) {
  Config c = default_config();
  EXPECT_EQ(gyro_id(c), 0U);  // backend none
  c.gyro.backend = GyroBackend::kIio;
  c.gyro.device = "bmg160";
  const std::uint32_t iio = gyro_id(c);
  EXPECT_NE(iio, 0U);
  c.gyro.noise_density *= 2.0;
  c.gyro.k_sigma = 7.0;
  EXPECT_EQ(gyro_id(c), iio);
  c.gyro.sign = -1;  // mounted upside down: the bias changes sign
  EXPECT_NE(gyro_id(c), iio);
  c.gyro.sign = 1;
  c.gyro.axis = GyroAxis::kX;
  EXPECT_NE(gyro_id(c), iio);
  c.gyro.axis = GyroAxis::kZ;
  c.gyro.device = "bmi088_gyro";
  EXPECT_NE(gyro_id(c), iio);
  c.gyro.backend = GyroBackend::kCan;
  const std::uint32_t can = gyro_id(c);
  c.can_gyro.scale *= 1.0 + 1e-12;  // another LSB, however close: the same number is another rate
  EXPECT_NE(gyro_id(c), can);
  c.can_gyro.scale = CanGyroSection{}.scale;
  c.gyro.seed += 1;  // a real gyro has no seed: the same id
  EXPECT_EQ(gyro_id(c), can);
  c = default_config();
  c.gyro.backend = GyroBackend::kSim;
  const std::uint32_t sim = gyro_id(c);
  c.gyro.seed += 1;  // another simulated chip
  EXPECT_NE(gyro_id(c), sim);
}

TEST(StatePersist, ResumeSectionIsReadAndChecked) {
  auto c = parse_config(
      "[resume]\nenabled = false\npath = \"/tmp/x.bin\"\nrate_hz = 20\n"
      "max_age = 2.5\n",
      "t.toml");
  ASSERT_TRUE(c) << c.error().message;
  EXPECT_FALSE(c->resume.enabled);
  EXPECT_EQ(c->resume.path, "/tmp/x.bin");
  EXPECT_EQ(c->resume.rate_hz, 20.0);
  EXPECT_EQ(c->resume.max_age, 2.5);
  // rate_hz above the loop rate (100 Hz by default) names the field and the range.
  auto bad = parse_config("[resume]\nrate_hz = 500\n", "t.toml");
  ASSERT_FALSE(bad);
  EXPECT_NE(bad.error().message.find("rate_hz"), std::string::npos) << bad.error().message;
  EXPECT_NE(bad.error().message.find("t.toml"), std::string::npos);
}

TEST(StatePersist, StateFileReasons) {
  const std::string path = ::testing::TempDir() + "state_persist_test.bin";
  std::remove(path.c_str());
  EXPECT_EQ(read_state_file(path).error().code, Errc::kNotFound);
  {
    std::ofstream f(path, std::ios::binary);
    f << std::string(loop::kStateFileBytes, '\x5a');
  }
  auto r = read_state_file(path);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, Errc::kCorrupt);
  EXPECT_NE(r.error().message.find(path), std::string::npos);
  // A valid record in slot 1 (sequence 3 is odd).
  loop::StateRecord rec;
  rec.sequence = 3;
  rec.counter_bits = 24;
  rec.pose = {1.0, 2.0, 3.0};
  rec.metres_per_count_left = rec.metres_per_count_right = 1e-3;  // a loop's kinematics are
  rec.wheelbase = 0.5;                                            // positive (decode_state)
  loop::StateBytes b{};
  loop::encode_state(rec, b);
  {
    std::fstream f(path, std::ios::binary | std::ios::in | std::ios::out);
    f.seekp(loop::kStateSlotBytes);
    f.write(reinterpret_cast<const char*>(b.data()), static_cast<std::streamsize>(b.size()));
  }
  auto ok = read_state_file(path);
  ASSERT_TRUE(ok) << ok.error().message;
  EXPECT_EQ(ok->sequence, 3u);
  EXPECT_EQ(ok->pose.y, 2.0);
}

}  // namespace
}  // namespace odo::fw
