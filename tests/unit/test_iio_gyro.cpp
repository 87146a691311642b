// IIO gyro backend against a fake sysfs tree and a fake character device (a regular file the
// test appends scans to) in a temporary directory; the scan-element type parser, extraction and
// layout against hand-worked bytes.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "odo/drivers/iio_gyro.hpp"
#include "odo/drivers/iio_scan.hpp"

namespace odo::drivers {
namespace {

namespace fs = std::filesystem;

TEST(IioScanType, ParsesWhatTheKernelPrints) {
  struct Row {
    const char* text;
    bool be, is_signed;
    int real, storage, shift, repeat;
  };
  const Row rows[] = {
      {"le:s16/16>>0\n", false, true, 16, 16, 0, 1},  // bmg160, as read from sysfs
      {"be:s12/16>>4", true, true, 12, 16, 4, 1},     // a 12-bit left-justified word
      {"le:s64/64>>0", false, true, 64, 64, 0, 1},    // the timestamp
      {"be:u24/32>>8", true, false, 24, 32, 8, 1},   {"le:S32/32>>0", false, true, 32, 32, 0, 1},
      {"le:s16/16X3>>0", false, true, 16, 16, 0, 3}, {"le:u8/8>>0", false, false, 8, 8, 0, 1},
  };
  for (const Row& r : rows) {
    const auto t = parse_iio_scan_type(r.text);
    ASSERT_TRUE(t.ok()) << r.text << ": " << t.error().message;
    EXPECT_EQ(t->big_endian, r.be) << r.text;
    EXPECT_EQ(t->is_signed, r.is_signed) << r.text;
    EXPECT_EQ(t->realbits, r.real) << r.text;
    EXPECT_EQ(t->storagebits, r.storage) << r.text;
    EXPECT_EQ(t->shift, r.shift) << r.text;
    EXPECT_EQ(t->repeat, r.repeat) << r.text;
  }
}

TEST(IioScanType, RejectsMalformedText) {
  const char* bad[] = {"",
                       "xe:s16/16>>0",
                       "le:x16/16>>0",
                       "le:s16/12>>0",
                       "le:s17/16>>0",
                       "le:s16/16>0",
                       "le:s16/16>>1",
                       "le:s16/16>>0 ",
                       "le:s0/16>>0",
                       "le:s16/16X0>>0",
                       "le:s-1/16>>0",
                       "le:s16/16>>0\n\n",
                       "le:s0016/16>>0",
                       "le:s65/64>>0",
                       "LE:s16/16>>0"};
  for (const char* b : bad) {
    const auto t = parse_iio_scan_type(b);
    ASSERT_FALSE(t.ok()) << "'" << b << "'";
    EXPECT_NE(t.error().message.find(std::string("'") + b), std::string::npos) << t.error().message;
  }
}

TEST(IioScanType, ExtractsByHand) {
  // le:s16: bytes ff 7f = 0x7fff = 32767; 00 80 = -32768; 85 ff = 0xff85 = -123.
  const IioScanType le16 = *parse_iio_scan_type("le:s16/16>>0");
  const std::uint8_t a[] = {0xff, 0x7f, 0x00, 0x80, 0x85, 0xff};
  EXPECT_EQ(iio_extract(a, le16), 32767);
  EXPECT_EQ(iio_extract(a + 2, le16), -32768);
  EXPECT_EQ(iio_extract(a + 4, le16), -123);
  // be:s12/16>>4: bytes ff f0 = 0xfff0 >> 4 = 0xfff = -1 in 12 bits; 7f f5 -> 0x7ff = 2047 (the
  // low nibble is other data and is masked away).
  const IioScanType be12 = *parse_iio_scan_type("be:s12/16>>4");
  const std::uint8_t b[] = {0xff, 0xf0, 0x7f, 0xf5};
  EXPECT_EQ(iio_extract(b, be12), -1);
  EXPECT_EQ(iio_extract(b + 2, be12), 2047);
  // le:u16: ff ff = 65535; le:s32: 00 00 00 80 = INT32_MIN; le:s64 timestamp 1 s = 1e9 ns.
  EXPECT_EQ(iio_extract(a, *parse_iio_scan_type("le:u16/16>>0")), 32767);
  const std::uint8_t c[] = {0xff, 0xff, 0x00, 0x00, 0x00, 0x80};
  EXPECT_EQ(iio_extract(c, *parse_iio_scan_type("le:u16/16>>0")), 65535);
  EXPECT_EQ(iio_extract(c + 2, *parse_iio_scan_type("le:s32/32>>0")), INT32_MIN);
  const std::uint8_t ts[] = {0x00, 0xca, 0x9a, 0x3b, 0, 0, 0, 0};  // 0x3b9aca00
  EXPECT_EQ(iio_extract(ts, *parse_iio_scan_type("le:s64/64>>0")), 1'000'000'000);
  std::int64_t lo = 0, hi = 0;
  iio_raw_limits(be12, lo, hi);
  EXPECT_EQ(lo, -2048);
  EXPECT_EQ(hi, 2047);
}

TEST(IioScanType, LayoutAsTheKernelComputesIt) {
  const IioScanType s16 = *parse_iio_scan_type("le:s16/16>>0");
  const IioScanType s64 = *parse_iio_scan_type("le:s64/64>>0");
  // x, y, z (2 bytes at 0, 2, 4) and the timestamp aligned to 8: 16 bytes (bmg160, all on).
  std::vector<IioScanElement> all{{0, s16}, {1, s16}, {2, s16}, {3, s64}};
  std::vector<std::size_t> off(4);
  EXPECT_EQ(iio_scan_layout(all, off), 16u);
  EXPECT_EQ(off, (std::vector<std::size_t>{0, 2, 4, 8}));
  // z and the timestamp only: z at 0, timestamp at 8, 16 bytes.
  std::vector<IioScanElement> zt{{2, s16}, {3, s64}};
  std::vector<std::size_t> o2(2);
  EXPECT_EQ(iio_scan_layout(zt, o2), 16u);
  EXPECT_EQ(o2, (std::vector<std::size_t>{0, 8}));
  // A 24-bit word in 32 and a 16-bit one: 4 + 2, padded to a multiple of 4: 8.
  std::vector<IioScanElement> mix{{0, *parse_iio_scan_type("be:s24/32>>8")}, {1, s16}};
  EXPECT_EQ(iio_scan_layout(mix, o2), 8u);
  EXPECT_EQ(o2, (std::vector<std::size_t>{0, 4}));
}

// FakeIio: a sysfs tree of one gyro (bmg160-like: x, y, z s16 le, timestamp s64) and its
// character device as a plain file.
class FakeIio : public ::testing::Test {
 protected:
  void SetUp() override {
    root_ = fs::temp_directory_path() /
            ("odo_iio_" + std::to_string(::getpid()) + "_" +
             ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(root_);
    make_device("iio:device0", "bmg160");
    make_device("iio:device1", "some_adc", false);
  }
  void TearDown() override { fs::remove_all(root_); }

  void make_device(const std::string& dev, const std::string& name, bool gyro = true) {
    const fs::path d = root_ / "sys" / dev;
    fs::create_directories(d / "scan_elements");
    fs::create_directories(d / "buffer");
    fs::create_directories(d / "trigger");
    fs::create_directories(root_ / "dev");
    put(d / "name", name + "\n");
    put(d / "buffer/enable", "0\n");
    put(d / "buffer/length", "2\n");
    put(d / "trigger/current_trigger", "\n");
    put(d / "current_timestamp_clock", "realtime\n");
    put(d / "sampling_frequency", "100\n");
    put(root_ / "dev" / dev, "");
    if (!gyro) {
      put(d / "in_voltage0_raw", "12\n");
      return;
    }
    put(d / "in_anglvel_scale", "0.000266\n");  // 500 deg/s range: 266 urad/s per LSB
    const char* axes[] = {"x", "y", "z"};
    for (int i = 0; i < 3; ++i) {
      const std::string ch = std::string("in_anglvel_") + axes[i];
      put(d / (ch + "_raw"), "0\n");
      put(d / "scan_elements" / (ch + "_en"), "1\n");
      put(d / "scan_elements" / (ch + "_index"), std::to_string(i) + "\n");
      put(d / "scan_elements" / (ch + "_type"), "le:s16/16>>0\n");
    }
    put(d / "scan_elements/in_timestamp_en", "0\n");
    put(d / "scan_elements/in_timestamp_index", "3\n");
    put(d / "scan_elements/in_timestamp_type", "le:s64/64>>0\n");
  }
  static void put(const fs::path& p, const std::string& text) {
    std::ofstream(p, std::ios::binary | std::ios::trunc) << text;
  }
  std::string get(const std::string& rel) const {
    std::ifstream f(root_ / "sys" / rel);
    std::string s;
    std::getline(f, s);
    return s;
  }
  // scan: appends one scan (z and timestamp enabled: z s16 at 0, timestamp at 8, 16 bytes).
  void scan(std::int16_t z, std::int64_t t_ns) {
    std::uint8_t b[16] = {};
    const auto u = static_cast<std::uint16_t>(z);
    b[0] = static_cast<std::uint8_t>(u);
    b[1] = static_cast<std::uint8_t>(u >> 8);
    for (int i = 0; i < 8; ++i) b[8 + i] = static_cast<std::uint8_t>(t_ns >> (8 * i));
    std::ofstream(root_ / "dev/iio:device0", std::ios::binary | std::ios::app)
        .write(reinterpret_cast<const char*>(b), 16);
  }
  IioGyroConfig config() const {
    IioGyroConfig c;
    c.device = "bmg160";
    c.sysfs_root = (root_ / "sys").string();
    c.dev_root = (root_ / "dev").string();
    return c;
  }
  fs::path root_;
};

TEST_F(FakeIio, BufferedReadsScaledMeanWithTimestamps) {
  IioGyroConfig c = config();
  c.sign = -1;  // mounted upside down
  c.trigger = "sysfstrig0";
  c.buffer_length = 64;
  c.expected_rate = 100.0;
  auto g = IioGyro::open(c);
  ASSERT_TRUE(g.ok()) << g.error().message;
  IioGyro& gyro = **g;
  // Set-up as the ABI wants it: only z and the timestamp enabled, monotonic clock, trigger,
  // length, then enable.
  EXPECT_EQ(get("iio:device0/scan_elements/in_anglvel_x_en"), "0");
  EXPECT_EQ(get("iio:device0/scan_elements/in_anglvel_y_en"), "0");
  EXPECT_EQ(get("iio:device0/scan_elements/in_anglvel_z_en"), "1");
  EXPECT_EQ(get("iio:device0/scan_elements/in_timestamp_en"), "1");
  EXPECT_EQ(get("iio:device0/current_timestamp_clock"), "monotonic");
  EXPECT_EQ(get("iio:device0/trigger/current_trigger"), "sysfstrig0");
  EXPECT_EQ(get("iio:device0/buffer/length"), "64");
  EXPECT_EQ(get("iio:device0/buffer/enable"), "1");
  EXPECT_EQ(gyro.scan_bytes(), 16u);
  EXPECT_DOUBLE_EQ(gyro.scale(), 0.000266);
  // Full scale: 32767 * 0.000266 = 8.716022 rad/s (500 deg/s = 8.726646: the LSB is rounded).
  EXPECT_NEAR(gyro.full_scale(), 8.716022, 1e-9);
  // Nothing yet: no samples, starting (not usable, not stale) before the timeout, rate 0.
  GyroSample s = gyro.read(1'000'000'000);
  EXPECT_EQ(s.samples, 0u);
  EXPECT_EQ(s.flags, kGyroStarting);
  EXPECT_EQ(s.rate_z, 0.0);
  EXPECT_EQ(s.counters.stale_events, 0u);
  // Three scans: 100, 200, -60 LSB at 1.001, 1.002, 1.003 s. Mean 80 LSB, sign -1:
  // -80 * 0.000266 = -0.02128 rad/s, stamp of the newest scan.
  scan(100, 1'001'000'000);
  scan(200, 1'002'000'000);
  scan(-60, 1'003'000'000);
  s = gyro.read(1'005'000'000);
  EXPECT_EQ(s.samples, 3u);
  EXPECT_NEAR(s.rate_z, -0.02128, 1e-15);
  EXPECT_EQ(s.stamp, 1'003'000'000);
  EXPECT_EQ(s.flags, kGyroOk);
  // A saturated word is flagged.
  scan(32767, 1'004'000'000);
  s = gyro.read(1'006'000'000);
  EXPECT_TRUE(s.flags & kGyroSaturated);
  EXPECT_EQ(s.counters.saturated, 1u);
  // No scan for more than 50 ms: stale, the last rate kept, one stale event.
  s = gyro.read(1'060'000'000);
  EXPECT_TRUE(s.flags & kGyroStale);
  EXPECT_EQ(s.samples, 0u);
  EXPECT_EQ(gyro.read(1'070'000'000).counters.stale_events, 1u);
}

TEST_F(FakeIio, PartialScanIsKeptForTheNextRead) {
  auto g = IioGyro::open(config());
  ASSERT_TRUE(g.ok()) << g.error().message;
  scan(10, 1'000'000);
  // Half of a scan (8 bytes) arrives, then the rest.
  std::uint8_t half[16] = {20, 0};
  half[8] = 0x80;  // timestamp 0x1e8480 = 2'000'000 ns
  half[9] = 0x84;
  half[10] = 0x1e;
  std::ofstream(root_ / "dev/iio:device0", std::ios::binary | std::ios::app)
      .write(reinterpret_cast<const char*>(half), 8);
  GyroSample s = (*g)->read(2'000'000);
  EXPECT_EQ(s.samples, 1u);
  EXPECT_NEAR(s.rate_z, 10 * 0.000266, 1e-15);
  std::ofstream(root_ / "dev/iio:device0", std::ios::binary | std::ios::app)
      .write(reinterpret_cast<const char*>(half + 8), 8);
  s = (*g)->read(3'000'000);
  EXPECT_EQ(s.samples, 1u);
  EXPECT_NEAR(s.rate_z, 20 * 0.000266, 1e-15);
  EXPECT_EQ(s.stamp, 2'000'000);
}

TEST_F(FakeIio, PolledReadsRawTimesScale) {
  IioGyroConfig c = config();
  c.mode = IioMode::kPolled;
  c.axis = IioAxis::kY;  // the chip's y points up on this robot
  put(root_ / "sys/iio:device0/in_anglvel_y_raw", "-123\n");
  put(root_ / "sys/iio:device0/in_anglvel_offset", "3\n");
  auto g = IioGyro::open(c);
  ASSERT_TRUE(g.ok()) << g.error().message;
  // (raw + offset) * scale = (-123 + 3) * 0.000266 = -0.03192 rad/s; stamp = the loop's now.
  GyroSample s = (*g)->read(42);
  EXPECT_EQ(s.samples, 1u);
  EXPECT_NEAR(s.rate_z, -0.03192, 1e-15);
  EXPECT_EQ(s.stamp, 42);
  // Polling leaves the buffer alone.
  EXPECT_EQ(get("iio:device0/buffer/enable"), "0");
  put(root_ / "sys/iio:device0/in_anglvel_y_raw", "12abc\n");
  s = (*g)->read(43);
  EXPECT_TRUE(s.flags & kGyroInvalid);
  EXPECT_NEAR(s.rate_z, -0.03192, 1e-15);  // the last good rate, flagged
}

TEST_F(FakeIio, DeviceByPath) {
  for (const std::string& p :
       {(root_ / "sys/iio:device0").string(), (root_ / "dev/iio:device0").string()}) {
    IioGyroConfig c = config();
    c.device = p;
    c.mode = IioMode::kPolled;
    auto g = IioGyro::open(c);
    ASSERT_TRUE(g.ok()) << p << ": " << g.error().message;
    EXPECT_EQ((*g)->name(), "bmg160");
  }
}

// open_error: the message of a failed open.
std::string open_error(const IioGyroConfig& c) {
  auto g = IioGyro::open(c);
  return g.ok() ? std::string("(opened)") : g.error().message;
}

TEST_F(FakeIio, ErrorsNameDeviceAndChannel) {
  IioGyroConfig c = config();
  c.device = "itg3200";
  std::string m = open_error(c);
  EXPECT_NE(m.find("'itg3200'"), std::string::npos) << m;
  EXPECT_NE(m.find("bmg160 (iio:device0)"), std::string::npos) << m;  // what is there
  c = config();
  c.device = "some_adc";
  m = open_error(c);
  EXPECT_NE(m.find("'some_adc'"), std::string::npos) << m;
  EXPECT_NE(m.find("channel in_anglvel_z missing"), std::string::npos) << m;
  c = config();
  c.device = (root_ / "dev/iio:device7").string();
  m = open_error(c);
  EXPECT_NE(m.find("iio:device7"), std::string::npos) << m;
  c = config();
  c.sign = 0;
  m = open_error(c);
  EXPECT_NE(m.find("sign = 0"), std::string::npos) << m;
  c = config();
  fs::remove(root_ / "sys/iio:device0/in_anglvel_scale");
  m = open_error(c);
  EXPECT_NE(m.find("bmg160"), std::string::npos) << m;
  EXPECT_NE(m.find("in_anglvel_z has no scale"), std::string::npos) << m;
  put(root_ / "sys/iio:device0/in_anglvel_scale", "-1\n");
  m = open_error(c);
  EXPECT_NE(m.find("not a positive number"), std::string::npos) << m;
}

TEST_F(FakeIio, BufferedErrors) {
  IioGyroConfig c = config();
  put(root_ / "sys/iio:device0/scan_elements/in_anglvel_z_type", "le:s16/8>>0\n");
  std::string m = open_error(c);
  EXPECT_NE(m.find("in_anglvel_z_type"), std::string::npos) << m;
  EXPECT_NE(m.find("le:s16/8>>0"), std::string::npos) << m;
  put(root_ / "sys/iio:device0/scan_elements/in_anglvel_z_type", "le:s16/16>>0\n");
  fs::remove(root_ / "sys/iio:device0/scan_elements/in_anglvel_z_en");
  m = open_error(c);
  EXPECT_NE(m.find("in_anglvel_z has no scan element"), std::string::npos) << m;
  EXPECT_NE(m.find("polled"), std::string::npos) << m;
  put(root_ / "sys/iio:device0/scan_elements/in_anglvel_z_en", "0\n");
  c.expected_rate = 200.0;  // the fake attribute keeps what is written: fine
  fs::remove(root_ / "sys/iio:device0/sampling_frequency");
  m = open_error(c);
  EXPECT_NE(m.find("sampling_frequency"), std::string::npos) << m;
}

TEST_F(FakeIio, TwoDevicesOfTheSameNameAreAmbiguous) {
  make_device("iio:device2", "bmg160");
  const std::string m = open_error(config());
  EXPECT_NE(m.find("2 IIO devices"), std::string::npos) << m;
}

}  // namespace
}  // namespace odo::drivers
