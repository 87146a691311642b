// Kernel tier: the IIO gyro backend against a real kernel IIO driver. The Bosch BMG160 driver
// (bmg160_i2c, which also serves the BMI088's gyro: Debian builds it as a module) is bound to an
// i2c-stub adapter, a kernel I2C adapter whose 256 registers at address 0x68 this test writes
// through /dev/i2c-N. The test puts known rates into the chip's rate registers and checks what
// the backend reads: raw * the driver's scale, with the driver's time stamps in buffered mode.
//
// Buffered mode needs a trigger: without an interrupt line (i2c-stub has none) the driver
// registers no data-ready trigger, and Debian's 6.1 kernel builds no software trigger
// (CONFIG_IIO_SYSFS_TRIGGER and CONFIG_IIO_HRTIMER_TRIGGER are not set). The buffered test uses
// iio-trig-sysfs.ko when `modprobe iio-trig-sysfs` finds it (tools/vm-run.sh builds it out of
// tree, as it does gpio-sim) or when ODO_IIO_TRIG_SYSFS_KO names a built module; otherwise it
// skips and says so.
#include <fcntl.h>
#include <linux/i2c-dev.h>
#include <linux/i2c.h>
#include <sys/ioctl.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>

#include "kernel_env.hpp"
#include "odo/drivers/iio_gyro.hpp"

namespace odo::test {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;

constexpr int kAddr = 0x68;
// BMG160 registers (drivers/iio/gyro/bmg160_core.c, data sheet BST-BMG160-DS000).
constexpr std::uint8_t kChipId = 0x00, kChipIdValue = 0x0F, kRateZLow = 0x06;

std::string slurp(const fs::path& p) {
  std::ifstream f(p);
  std::string s;
  std::getline(f, s);
  return s;
}

TimeNs monotonic_ns() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return TimeNs{ts.tv_sec} * kNsPerSecond + ts.tv_nsec;
}

// StubBmg160: i2c-stub with a BMG160 at 0x68 and the bmg160 IIO device bound to it.
class StubBmg160 {
 public:
  StubBmg160() {
    bus_ = i2c_stub_bus();
    if (bus_.empty()) {
      error_ = "i2c-stub cannot be loaded with the chips of kI2cStubChips (modprobe i2c-stub)";
      return;
    }
    if (run("modprobe i2c-dev && modprobe bmg160_i2c") != 0) {
      error_ = "modprobe i2c-dev / bmg160_i2c failed";
      return;
    }
    fd_ = ::open(("/dev/" + bus_).c_str(), O_RDWR);
    // I2C_SLAVE_FORCE: the address is (about to be) claimed by the driver.
    if (fd_ < 0 || ::ioctl(fd_, I2C_SLAVE_FORCE, kAddr) < 0) {
      error_ = "/dev/" + bus_ + ": cannot address 0x68";
      return;
    }
    // The chip id must read 0x0F before the driver probes.
    if (!write_reg(kChipId, kChipIdValue) ||
        run("echo bmg160 0x68 > /sys/bus/i2c/devices/" + bus_ + "/new_device") != 0) {
      error_ = "binding bmg160 to " + bus_ + " failed";
      return;
    }
    // The probe resets the chip and waits 30 + 80 ms for it.
    for (int i = 0; i < 300 && iio_dir_.empty(); ++i) {
      for (const auto& e : fs::directory_iterator("/sys/bus/iio/devices")) {
        if (slurp(e.path() / "name") == "bmg160") iio_dir_ = e.path().string();
      }
      if (iio_dir_.empty()) std::this_thread::sleep_for(10ms);
    }
    if (iio_dir_.empty()) error_ = "bmg160 bound but no IIO device appeared (see dmesg)";
  }
  ~StubBmg160() {
    if (fd_ >= 0) ::close(fd_);
    if (!bus_.empty()) run("echo 0x68 > /sys/bus/i2c/devices/" + bus_ + "/delete_device");
    run("rmmod bmg160_i2c bmg160_core i2c-stub 2>/dev/null");
  }
  const std::string& error() const { return error_; }
  const std::string& iio_dir() const { return iio_dir_; }

  // write_reg: one SMBus byte write into the stub's register file.
  bool write_reg(std::uint8_t reg, std::uint8_t value) const {
    i2c_smbus_data d{};
    d.byte = value;
    i2c_smbus_ioctl_data a{I2C_SMBUS_WRITE, reg, I2C_SMBUS_BYTE_DATA, &d};
    return ::ioctl(fd_, I2C_SMBUS, &a) == 0;
  }
  // set_rate_z: the z rate registers (little endian, two's complement) = raw.
  bool set_rate_z(std::int16_t raw) const {
    const auto u = static_cast<std::uint16_t>(raw);
    return write_reg(kRateZLow, static_cast<std::uint8_t>(u & 0xFF)) &&
           write_reg(kRateZLow + 1, static_cast<std::uint8_t>(u >> 8));
  }

 private:
  std::string error_, bus_, iio_dir_;
  int fd_ = -1;
};

TEST(KernelIioGyro, Bmg160OnI2cStubPolled) {
  ODO_REQUIRE_VM();
  StubBmg160 chip;
  ASSERT_TRUE(chip.error().empty()) << chip.error();
  drivers::IioGyroConfig c;
  c.device = "bmg160";
  c.mode = drivers::IioMode::kPolled;
  auto g = drivers::IioGyro::open(c);
  ASSERT_TRUE(g.ok()) << g.error().message;
  drivers::IioGyro& gyro = **g;
  // The driver's default range is 500 deg/s: in_anglvel_scale = 0.000266 rad/s per LSB
  // (bmg160_scale_table: 266 urad/s; 500 deg/s / 32768 = 2.6632e-4 rad/s).
  EXPECT_NEAR(gyro.scale(), 0.000266, 1e-12);
  for (const std::int16_t raw : {1234, -2000, 0, 32767, -32768}) {
    ASSERT_TRUE(chip.set_rate_z(raw));
    const GyroSample s = gyro.read(monotonic_ns());
    EXPECT_EQ(s.samples, 1u) << raw;
    EXPECT_NEAR(s.rate_z, raw * 0.000266, 1e-12) << raw;
    const bool end = raw == 32767 || raw == -32768;
    EXPECT_EQ((s.flags & kGyroSaturated) != 0, end) << raw;
  }
  // Mounting sign: the same chip read upside down.
  c.sign = -1;
  auto flipped = drivers::IioGyro::open(c);
  ASSERT_TRUE(flipped.ok()) << flipped.error().message;
  ASSERT_TRUE(chip.set_rate_z(1234));
  EXPECT_NEAR((*flipped)->read(monotonic_ns()).rate_z, -1234 * 0.000266, 1e-12);
  // Cost of a polled read: a synchronous bus transaction in the caller's thread (here to the
  // stub, under TCG, so no bus time at all), plus whatever the driver does first: bmg160 takes a
  // runtime-PM reference per read, and after 2 s without one (its autosuspend delay) the resume
  // sleeps 80 ms (BMG160_MAX_STARTUP_TIME_MS) before the read: a loop polling it would stall.
  auto time_read = [&] {
    const auto t0 = std::chrono::steady_clock::now();
    (void)gyro.read(monotonic_ns());
    return std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - t0).count();
  };
  const int n = 200;
  double sum = 0.0, worst = 0.0;
  for (int i = 0; i < n; ++i) {
    const double us = time_read();
    sum += us;
    worst = std::max(worst, us);
  }
  std::this_thread::sleep_for(2500ms);
  const double after_idle = time_read();
  std::printf(
      "polled read: mean %.1f us, max %.1f us over %d reads; first read after 2.5 s "
      "idle: %.1f us (bmg160 on i2c-stub, in the VM)\n",
      sum / n, worst, n, after_idle);
  RecordProperty("polled_read_us", std::to_string(sum / n));
  RecordProperty("polled_read_after_idle_us", std::to_string(after_idle));
}

// load_sysfs_trigger: the iio-trig-sysfs module, or why it is not there.
std::string load_sysfs_trigger() {
  if (fs::exists("/sys/bus/iio/devices/iio_sysfs_trigger")) return {};
  if (run("modprobe iio-trig-sysfs 2>/dev/null") == 0) return {};
  const char* ko = std::getenv("ODO_IIO_TRIG_SYSFS_KO");
  if (ko != nullptr && run(std::string("insmod ") + ko) == 0) return {};
  return "no iio-trig-sysfs module: Debian's 6.1 kernel does not build CONFIG_IIO_SYSFS_TRIGGER "
         "(tools/vm-run.sh must build it out of tree, as gpio-sim; or set ODO_IIO_TRIG_SYSFS_KO)";
}

TEST(KernelIioGyro, Bmg160OnI2cStubBufferedWithTimestamps) {
  ODO_REQUIRE_VM();
  if (const std::string why = load_sysfs_trigger(); !why.empty()) GTEST_SKIP() << why;
  StubBmg160 chip;
  ASSERT_TRUE(chip.error().empty()) << chip.error();
  run("echo 7 > /sys/bus/iio/devices/iio_sysfs_trigger/add_trigger 2>/dev/null");
  std::string trig_dir;
  for (const auto& e : fs::directory_iterator("/sys/bus/iio/devices")) {
    if (slurp(e.path() / "name") == "sysfstrig7") trig_dir = e.path().string();
  }
  ASSERT_FALSE(trig_dir.empty()) << "sysfstrig7 did not appear";
  drivers::IioGyroConfig c;
  c.device = chip.iio_dir();  // by path this time
  c.trigger = "sysfstrig7";
  c.buffer_length = 16;
  auto g = drivers::IioGyro::open(c);
  ASSERT_TRUE(g.ok()) << g.error().message;
  drivers::IioGyro& gyro = **g;
  EXPECT_EQ(gyro.scan_bytes(), 16u);  // z (s16 at 0) and the timestamp (s64 at 8)
  EXPECT_EQ(slurp(chip.iio_dir() + "/current_timestamp_clock"), "monotonic");
  const int fire = ::open((trig_dir + "/trigger_now").c_str(), O_WRONLY);
  ASSERT_GE(fire, 0);
  for (const std::int16_t raw : {1234, -2000, 77, 32767}) {
    ASSERT_TRUE(chip.set_rate_z(raw));
    const TimeNs before = monotonic_ns();
    ASSERT_EQ(::write(fire, "1", 1), 1);
    const TimeNs after_fire = monotonic_ns();
    // The scan is taken by the driver's threaded handler: poll without blocking until it is in.
    GyroSample s;
    for (int i = 0; i < 1000 && s.samples == 0; ++i) {
      s = gyro.read(monotonic_ns());
      if (s.samples == 0) std::this_thread::sleep_for(1ms);
    }
    ASSERT_EQ(s.samples, 1u) << raw;
    EXPECT_NEAR(s.rate_z, raw * 0.000266, 1e-12) << raw;
    // The driver stamps the scan when the trigger fires (iio_pollfunc_store_time), on the
    // monotonic clock the backend selected: within the write of trigger_now.
    EXPECT_GE(s.stamp, before) << raw;
    EXPECT_LE(s.stamp, after_fire) << raw;
    EXPECT_EQ((s.flags & kGyroSaturated) != 0, raw == 32767) << raw;
  }
  // Several scans between two reads are all averaged: 100, 200, 600 LSB -> 300 LSB.
  for (const std::int16_t raw : {100, 200, 600}) {
    ASSERT_TRUE(chip.set_rate_z(raw));
    ASSERT_EQ(::write(fire, "1", 1), 1);
    // Wait until the handler has read the registers before changing them again.
    std::this_thread::sleep_for(50ms);
  }
  GyroSample s = gyro.read(monotonic_ns());
  EXPECT_EQ(s.samples, 3u);
  EXPECT_NEAR(s.rate_z, 300 * 0.000266, 1e-12);
  ::close(fire);
  // Cost of a read that finds the buffer empty (the loop's common case between samples).
  const int n = 200;
  const auto t0 = std::chrono::steady_clock::now();
  for (int i = 0; i < n; ++i) s = gyro.read(monotonic_ns());
  const double us =
      std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - t0).count() / n;
  EXPECT_EQ(s.samples, 0u);
  std::printf("buffered read of an empty buffer: %.1f us (in the VM)\n", us);
  RecordProperty("buffered_read_us", std::to_string(us));
}

TEST(KernelIioGyro, MissingChannelNamesDeviceAndChannel) {
  ODO_REQUIRE_VM();
  StubBmg160 chip;
  ASSERT_TRUE(chip.error().empty()) << chip.error();
  drivers::IioGyroConfig c;
  c.device = "bmg160_nonexistent";
  auto g = drivers::IioGyro::open(c);
  ASSERT_FALSE(g.ok());
  EXPECT_NE(g.error().message.find("bmg160 (iio:device"), std::string::npos) << g.error().message;
  // bmg160 without a trigger: enabling the buffer fails and says what to do.
  c.device = "bmg160";
  g = drivers::IioGyro::open(c);
  ASSERT_FALSE(g.ok());
  EXPECT_NE(g.error().message.find("buffer/enable"), std::string::npos) << g.error().message;
  EXPECT_NE(g.error().message.find("trigger"), std::string::npos) << g.error().message;
}

}  // namespace
}  // namespace odo::test
