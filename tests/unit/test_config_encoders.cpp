// Config sections [hctl1100], [gpio], [can_encoder] (issue 5) and [can_gyro] (issue 16):
// values, defaults, and clear errors.
#include <gtest/gtest.h>

#include <cstdio>
#include <string>

#include "odo/drivers/can_encoder.hpp"
#include "odo/drivers/can_gyro.hpp"
#include "odo/drivers/gpio_quadrature.hpp"
#include "odo/drivers/hctl1100_encoder.hpp"
#include "odo/firmware/config.hpp"
#include "odo/sim/hctl1100_model.hpp"
#include "odo/sim/sim_can_bus.hpp"

namespace odo::fw {
namespace {

TEST(ConfigEncoders, ReadsHctl1100Section) {
  auto c = parse_config(R"(
[encoder]
backend = "hctl1100"
[hctl1100]
chip = "/dev/gpiochip2"
ad0 = 5
ad7 = 21
ale = 22
oe = 23
rw = 24
cs_left = 25
cs_right = 26
control_active_low = false
settle = 0.0001
max_speed = 2.5
agree_window = 8
max_attempts = 6
reverse_right = true
)",
                        "h.toml");
  ASSERT_TRUE(c.ok()) << c.error().message;
  EXPECT_EQ(c->encoder.backend, EncoderKind::kHctl1100);
  const Hctl1100Section& h = c->hctl1100;
  EXPECT_EQ(h.bus, HctlBus::kGpio);
  EXPECT_EQ(h.chip, "/dev/gpiochip2");
  EXPECT_EQ(h.ad[0], 5);
  EXPECT_EQ(h.ad[1], 1);  // default kept
  EXPECT_EQ(h.ad[7], 21);
  EXPECT_EQ(h.ale, 22);
  EXPECT_EQ(h.oe, 23);
  EXPECT_EQ(h.rw, 24);
  EXPECT_EQ(h.cs_left, 25);
  EXPECT_EQ(h.cs_right, 26);
  EXPECT_FALSE(h.control_active_low);
  EXPECT_DOUBLE_EQ(h.settle, 1e-4);
  EXPECT_DOUBLE_EQ(h.max_speed, 2.5);
  EXPECT_EQ(h.agree_window, 8);
  EXPECT_EQ(h.max_attempts, 6);
  EXPECT_FALSE(h.reverse_left);
  EXPECT_TRUE(h.reverse_right);
}

TEST(ConfigEncoders, ReadsGpioSection) {
  auto c = parse_config(R"(
[encoder]
backend = "gpio"
[gpio]
chip = "gpio-sim.0-node0"
left_a = 17
left_b = 18
left_index = 4
right_a = 22
right_b = 23
active_low = true
batch = 128
reorder_window = 0.002
idle_check = 0.1
reverse_left = true
)",
                        "g.toml");
  ASSERT_TRUE(c.ok()) << c.error().message;
  const GpioSection& g = c->gpio;
  EXPECT_EQ(g.chip, "gpio-sim.0-node0");
  EXPECT_EQ(g.left_a, 17);
  EXPECT_EQ(g.left_b, 18);
  EXPECT_EQ(g.left_index, 4);
  EXPECT_EQ(g.right_a, 22);
  EXPECT_EQ(g.right_b, 23);
  EXPECT_EQ(g.right_index, -1);
  EXPECT_TRUE(g.active_low);
  EXPECT_EQ(g.batch, 128);
  EXPECT_DOUBLE_EQ(g.reorder_window, 0.002);
  EXPECT_DOUBLE_EQ(g.idle_check, 0.1);
  EXPECT_TRUE(g.reverse_left);
  EXPECT_FALSE(g.reverse_right);
}

TEST(ConfigEncoders, CanEncoderDefaults) {
  auto c = parse_config("[encoder]\nbackend = \"can\"\n", "c.toml");
  ASSERT_TRUE(c.ok()) << c.error().message;
  const CanEncoderSection& e = c->can_encoder;
  EXPECT_EQ(e.bus, CanEncoderBus::kSocketCan);
  EXPECT_EQ(e.interface, "can0");
  EXPECT_EQ(e.protocol, CanEncoderProtocol::kOdrive);
  EXPECT_EQ(e.node_left, 0);
  EXPECT_EQ(e.node_right, 1);
  EXPECT_DOUBLE_EQ(e.timeout, 0.1);
  EXPECT_DOUBLE_EQ(e.request_rate, 0.0);  // requests off: ODrive sends cyclically
  EXPECT_EQ(e.max_frames_per_read, 64);
}

TEST(ConfigEncoders, ReadsCanEncoderGenericLayout) {
  auto c = parse_config(R"(
[encoder]
backend = "can"
[can_encoder]
bus = "socketcan"
interface = "vcan0"
protocol = "generic"
extended = true
left_id = 0x18FF0010
right_id = 0x18FF0010
left_offset = 0
right_offset = 4
width = 32
signed = false
byte_order = "big"
timeout = 0.25
max_speed = 1.5
request_rate = 50
max_frames_per_read = 128
reverse_left = true
)",
                        "c.toml");
  ASSERT_TRUE(c.ok()) << c.error().message;
  const CanEncoderSection& e = c->can_encoder;
  EXPECT_EQ(e.interface, "vcan0");
  EXPECT_EQ(e.protocol, CanEncoderProtocol::kGeneric);
  EXPECT_TRUE(e.extended);
  EXPECT_EQ(e.left_id, 0x18FF0010);
  EXPECT_EQ(e.right_id, 0x18FF0010);
  EXPECT_EQ(e.left_offset, 0);
  EXPECT_EQ(e.right_offset, 4);
  EXPECT_EQ(e.width, 32);
  EXPECT_FALSE(e.is_signed);
  EXPECT_EQ(e.byte_order, ByteOrder::kBig);
  EXPECT_DOUBLE_EQ(e.timeout, 0.25);
  EXPECT_DOUBLE_EQ(e.max_speed, 1.5);
  EXPECT_DOUBLE_EQ(e.request_rate, 50.0);
  EXPECT_EQ(e.max_frames_per_read, 128);
  EXPECT_TRUE(e.reverse_left);
  EXPECT_FALSE(e.reverse_right);
}

// Several wheels per side (issue 38): a list per side, one node id (or frame id) per wheel.
TEST(ConfigEncoders, ReadsCanEncoderWheelListsPerSide) {
  auto c = parse_config(
      "[encoder]\nbackend = \"can\"\nwheels_per_side = 2\n[can_encoder]\nnode_left = [0, 2]\n"
      "node_right = [1, 3]\n",
      "c.toml");
  ASSERT_TRUE(c.ok()) << c.error().message;
  const CanEncoderSection& e = c->can_encoder;
  EXPECT_EQ(e.wheels_per_side, 2);
  EXPECT_EQ(e.node_left, 0);
  EXPECT_EQ(e.more_node_left[0], 2);
  EXPECT_EQ(e.node_right, 1);
  EXPECT_EQ(e.more_node_right[0], 3);
  // Generic: one offset for the side's wheels, or a list as long as the ids.
  c = parse_config(R"(
[can_encoder]
protocol = "generic"
left_id = [0x100, 0x102, 0x104]
right_id = [0x101, 0x101, 0x105]
left_offset = 2
right_offset = [0, 4, 0]
)",
                   "c.toml");
  ASSERT_TRUE(c.ok()) << c.error().message;
  const CanEncoderSection& g = c->can_encoder;
  EXPECT_EQ(g.wheels_per_side, 3);
  EXPECT_EQ(g.left_id, 0x100);
  EXPECT_EQ(g.more_left_id[1], 0x104);
  EXPECT_EQ(g.more_left_offset[0], 2);
  EXPECT_EQ(g.more_left_offset[1], 2);
  EXPECT_EQ(g.more_right_id[0], 0x101);
  EXPECT_EQ(g.more_right_offset[0], 4);
  // One integer is one wheel per side, as before.
  c = parse_config("[can_encoder]\nnode_left = [4]\nnode_right = 5\n", "c.toml");
  ASSERT_TRUE(c.ok()) << c.error().message;
  EXPECT_EQ(c->can_encoder.wheels_per_side, 1);
  EXPECT_EQ(c->can_encoder.node_left, 4);
}

TEST(ConfigEncoders, ReadsGpioLinePairsPerWheel) {
  auto c = parse_config(R"(
[encoder]
backend = "gpio"
wheels_per_side = 2
[gpio]
left_a = [17, 5]
left_b = [18, 6]
right_a = [22, 12]
right_b = [23, 13]
)",
                        "c.toml");
  ASSERT_TRUE(c.ok()) << c.error().message;
  const GpioSection& g = c->gpio;
  EXPECT_EQ(g.wheels_per_side, 2);
  EXPECT_EQ(g.left_a, 17);
  EXPECT_EQ(g.more_left_a[0], 5);
  EXPECT_EQ(g.more_left_b[0], 6);
  EXPECT_EQ(g.right_b, 23);
  EXPECT_EQ(g.more_right_b[0], 13);
}

TEST(ConfigEncoders, CanGyroDefaults) {
  auto c = parse_config("[gyro]\nbackend = \"can\"\n", "g.toml");
  ASSERT_TRUE(c.ok()) << c.error().message;
  EXPECT_EQ(c->gyro.backend, GyroBackend::kCan);
  const CanGyroSection& g = c->can_gyro;
  EXPECT_EQ(g.bus, CanEncoderBus::kSocketCan);
  EXPECT_EQ(g.interface, "can0");
  EXPECT_EQ(g.id, 0x120);
  EXPECT_FALSE(g.extended);
  EXPECT_EQ(g.offset, 0);
  EXPECT_EQ(g.width, 16);
  EXPECT_TRUE(g.is_signed);
  EXPECT_EQ(g.byte_order, ByteOrder::kLittle);
  // 2000 deg/s over the 2^15 steps of a signed 16-bit word: 34.906585 / 32768 rad/s.
  EXPECT_NEAR(g.scale, 1.0652644e-3, 1e-10);
  EXPECT_DOUBLE_EQ(g.rate_offset, 0.0);
  EXPECT_EQ(g.max_frames_per_read, 64);
  EXPECT_DOUBLE_EQ(g.sim_stop_after, -1.0);
}

TEST(ConfigEncoders, ReadsCanGyroSection) {
  auto c = parse_config(R"(
[gyro]
backend = "can"
sign = -1
[can_gyro]
bus = "sim"
interface = "vcan1"
extended = true
id = 0x18FF0120
offset = 4
width = 32
signed = false
byte_order = "big"
scale = 1e-7
rate_offset = -214.7483648
max_frames_per_read = 8
sim_stop_after = 3.5
)",
                        "g.toml");
  ASSERT_TRUE(c.ok()) << c.error().message;
  EXPECT_EQ(c->gyro.sign, -1);
  const CanGyroSection& g = c->can_gyro;
  EXPECT_EQ(g.bus, CanEncoderBus::kSim);
  EXPECT_EQ(g.interface, "vcan1");
  EXPECT_TRUE(g.extended);
  EXPECT_EQ(g.id, 0x18FF0120);
  EXPECT_EQ(g.offset, 4);
  EXPECT_EQ(g.width, 32);
  EXPECT_FALSE(g.is_signed);
  EXPECT_EQ(g.byte_order, ByteOrder::kBig);
  EXPECT_DOUBLE_EQ(g.scale, 1e-7);
  EXPECT_DOUBLE_EQ(g.rate_offset, -214.7483648);
  EXPECT_EQ(g.max_frames_per_read, 8);
  EXPECT_DOUBLE_EQ(g.sim_stop_after, 3.5);
}

struct Bad {
  const char* text;
  const char* expect;
};
class ConfigEncodersReject : public ::testing::TestWithParam<Bad> {};

TEST_P(ConfigEncodersReject, NamesFileLineField) {
  auto c = parse_config(GetParam().text, "bad.toml");
  ASSERT_FALSE(c.ok());
  EXPECT_NE(c.error().message.find(GetParam().expect), std::string::npos) << c.error().message;
}

INSTANTIATE_TEST_SUITE_P(
    Cases, ConfigEncodersReject,
    ::testing::Values(
        Bad{"[hctl1100]\nad3 = 5000\n", "bad.toml:2: hctl1100.ad3 = 5000 is outside"},
        Bad{"[hctl1100]\nbus = \"spi\"\n", "bad.toml:2: hctl1100.bus"},
        Bad{"[hctl1100]\nagree_window = 200\n", "bad.toml:2: hctl1100.agree_window"},
        Bad{"[hctl1100]\nad8 = 1\n", "bad.toml:2: hctl1100.ad8 is not a known setting"},
        Bad{"[gpio]\nleft_index = -2\n", "bad.toml:2: gpio.left_index = -2 is outside"},
        Bad{"[gpio]\n\nbatch = 0\n", "bad.toml:3: gpio.batch"},
        Bad{"[gpio]\nreorder_window = 1\n", "bad.toml:2: gpio.reorder_window"},
        Bad{"[gpio]\nleft_c = 1\n", "bad.toml:2: gpio.left_c is not a known setting"},
        Bad{"[can_encoder]\nbus = \"usb\"\n",
            "bad.toml:2: can_encoder.bus = \"usb\" is not one of: socketcan, sim"},
        Bad{"[can_encoder]\nprotocol = \"canopen\"\n",
            "bad.toml:2: can_encoder.protocol = \"canopen\" is not one of: odrive, generic"},
        Bad{"[can_encoder]\nnode_left = 64\n",
            "bad.toml:2: can_encoder.node_left = 64 is outside the allowed range [0, 63]"},
        Bad{"[can_encoder]\nnode_right = 0\n",
            "bad.toml:2: can_encoder.node_right = 0 is the left wheel's node id too"},
        // 11-bit ids end at 0x7FF = 2047; 29-bit ones at 0x1FFFFFFF = 536870911.
        Bad{"[can_encoder]\nleft_id = 2048\n",
            "bad.toml:2: can_encoder.left_id = 2048 is outside the allowed range [0, 2047]"},
        Bad{"[can_encoder]\nextended = true\nright_id = 0x20000000\n",
            "bad.toml:3: can_encoder.right_id = 536870912 is outside the allowed range [0, "
            "536870911]"},
        Bad{"[can_encoder]\nwidth = 8\n",
            "bad.toml:2: can_encoder.width = 8 is outside the allowed range [16, 64]"},
        Bad{"[can_encoder]\nwidth = 20\n",
            "bad.toml:2: can_encoder.width = 20 must be a whole number of bytes"},
        // 32 bits are 4 bytes: the last offset that fits 8 data bytes is 4.
        Bad{"[can_encoder]\nleft_offset = 5\n",
            "bad.toml:2: can_encoder.left_offset = 5 is outside the allowed range [0, 4]"},
        Bad{"[can_encoder]\nwidth = 64\nright_offset = 1\n",
            "bad.toml:3: can_encoder.right_offset = 1 is outside the allowed range [0, 0]"},
        Bad{"[can_encoder]\nprotocol = \"generic\"\nleft_id = 5\nright_id = 5\n",
            "can_encoder.right_offset = 0: both wheels would read the same bytes of frame 5"},
        Bad{"[can_encoder]\nbyte_order = \"middle\"\n",
            "bad.toml:2: can_encoder.byte_order = \"middle\" is not one of: little, big"},
        Bad{"[can_encoder]\nsigned = 1\n", "bad.toml:2: can_encoder.signed must be true or false"},
        Bad{"[can_encoder]\nmax_frames_per_read = 0\n",
            "bad.toml:2: can_encoder.max_frames_per_read = 0 is outside the allowed range [1, "
            "4096]"},
        Bad{"[can_encoder]\nnode = 1\n", "bad.toml:2: can_encoder.node is not a known setting"},
        Bad{"[gyro]\nbackend = \"spi\"\n",
            "bad.toml:2: gyro.backend = \"spi\" is not one of: none, sim, iio, can"},
        Bad{"[can_gyro]\nbus = \"usb\"\n",
            "bad.toml:2: can_gyro.bus = \"usb\" is not one of: socketcan, sim"},
        Bad{"[can_gyro]\ninterface = \"\"\n", "bad.toml:2: can_gyro.interface = \"\" must be"},
        Bad{"[can_gyro]\nid = 2048\n",
            "bad.toml:2: can_gyro.id = 2048 is outside the allowed range [0, 2047]"},
        // A rate of 8 bits would be too coarse, one of 40 or more is no MEMS output.
        Bad{"[can_gyro]\nwidth = 8\n",
            "bad.toml:2: can_gyro.width = 8 is outside the allowed range [16, 32]"},
        Bad{"[can_gyro]\nwidth = 40\n",
            "bad.toml:2: can_gyro.width = 40 is outside the allowed range [16, 32]"},
        Bad{"[can_gyro]\nwidth = 20\n", "bad.toml:2: can_gyro.width = 20 must be 16, 24 or 32"},
        // 24 bits are 3 bytes: the last offset that fits 8 data bytes is 5.
        Bad{"[can_gyro]\nwidth = 24\noffset = 6\n",
            "bad.toml:3: can_gyro.offset = 6 is outside the allowed range [0, 5]"},
        Bad{"[can_gyro]\nscale = 0\n", "bad.toml:2: can_gyro.scale = 0 is outside"},
        Bad{"[can_gyro]\nrate_offset = 1e4\n", "bad.toml:2: can_gyro.rate_offset = 10000"},
        Bad{"[can_gyro]\nbyte_order = \"middle\"\n",
            "bad.toml:2: can_gyro.byte_order = \"middle\" is not one of: little, big"},
        Bad{"[can_gyro]\nmax_frames_per_read = 4097\n",
            "bad.toml:2: can_gyro.max_frames_per_read = 4097 is outside the allowed range [1, "
            "4096]"},
        Bad{"[can_gyro]\nsim_stop_after = -2\n", "bad.toml:2: can_gyro.sim_stop_after = -2"},
        Bad{"[can_gyro]\nnode = 1\n", "bad.toml:2: can_gyro.node is not a known setting"},
        // A simulated gyro measures the simulated robot: on real encoders it is refused here,
        // at the line that asks for it, before any hardware is opened.
        Bad{"[encoder]\nbackend = \"gpio\"\n[gyro]\nbackend = \"sim\"\n",
            "bad.toml:4: gyro.backend = \"sim\" is a simulated gyro, which needs the simulated "
            "robot, but encoder.backend = \"gpio\" reads real hardware"},
        Bad{"[encoder]\nbackend = \"can\"\n[gyro]\nbackend = \"can\"\n[can_gyro]\nbus = "
            "\"sim\"\n",
            "bad.toml:6: can_gyro.bus = \"sim\" with gyro.backend = \"can\" is a simulated gyro, "
            "which needs the simulated robot, but encoder.backend = \"can\" reads real "
            "hardware"}));

INSTANTIATE_TEST_SUITE_P(
    WheelLists, ConfigEncodersReject,
    ::testing::Values(
        Bad{"[can_encoder]\nnode_left = [0, 64]\n",
            "bad.toml:2: can_encoder.node_left[1] = 64 is outside the allowed range [0, 63]"},
        Bad{"[can_encoder]\nnode_left = [0, 2, 4, 6, 8]\n",
            "bad.toml:2: can_encoder.node_left has 5 entries: give 1..4"},
        Bad{"[can_encoder]\nnode_left = []\n",
            "bad.toml:2: can_encoder.node_left has 0 entries: give 1..4"},
        Bad{"[can_encoder]\nnode_left = [0, \"2\"]\n",
            "bad.toml:2: can_encoder.node_left[1] must be an integer"},
        Bad{"[can_encoder]\nnode_left = [0, 2]\nnode_right = 1\n",
            "bad.toml:3: can_encoder.node_right lists 1 wheel(s) but node_left lists 2: both "
            "sides need the same number of wheels"},
        Bad{"[can_encoder]\nnode_left = [0, 2]\nnode_right = [1, 2]\n",
            "bad.toml:3: can_encoder.node_right gives node id 2 to two wheels (each wheel needs "
            "its own axis)"},
        Bad{"[can_encoder]\nprotocol = \"generic\"\nleft_id = [0x100, 0x102]\n"
            "right_id = [0x101, 0x103]\nleft_offset = [0, 4, 0]\n",
            "bad.toml:5: can_encoder.left_offset lists 3 wheel(s) but left_id lists 2: give one "
            "offset for all, or one per wheel"},
        Bad{"[can_encoder]\nprotocol = \"generic\"\nleft_id = [0x100, 0x100]\n"
            "right_id = [0x101, 0x103]\n",
            "bad.toml:3: can_encoder.left_id puts two wheels on the same bytes (frame 256, offset "
            "0)"},
        Bad{"[encoder]\nbackend = \"can\"\nwheels_per_side = 2\n[can_encoder]\nnode_left = 0\n",
            "bad.toml:5: can_encoder.node_left lists 1 wheel(s) but encoder.wheels_per_side = 2: "
            "give one per wheel of the side"},
        Bad{"[encoder]\nbackend = \"can\"\nwheels_per_side = 2\n[can_encoder]\n"
            "protocol = \"generic\"\nleft_id = [1, 2, 3]\nright_id = [4, 5, 6]\n",
            "bad.toml:6: can_encoder.left_id lists 3 wheel(s) but encoder.wheels_per_side = 2"},
        Bad{"[gpio]\nleft_a = [17, 5]\nleft_b = 18\n",
            "bad.toml:3: gpio.left_b lists 1 wheel(s) but left_a lists 2: one A/B pair per "
            "wheel, both sides alike"},
        Bad{"[encoder]\nbackend = \"gpio\"\nwheels_per_side = 2\n[gpio]\nleft_a = 17\n",
            "bad.toml:5: gpio.left_a lists 1 wheel(s) but encoder.wheels_per_side = 2"},
        Bad{"[gpio]\nright_b = [3, 1024]\n",
            "bad.toml:2: gpio.right_b[1] = 1024 is outside the allowed range [0, 1023]"},
        Bad{"[can_encoder]\nbus = \"sim\"\nnode_left = [0, 2]\nnode_right = [1, 3]\n",
            "bad.toml:2: can_encoder.bus = \"sim\" simulates one ODrive axis per side: 2 wheels "
            "per side need bus = \"socketcan\""}));

// The simulated gyro goes with every simulated robot: encoder backend sim, or the counter chip
// and the CAN motor controllers on their simulated buses.
TEST(ConfigEncoders, SimulatedGyroOnEverySimulatedRobot) {
  for (const char* enc : {"backend = \"sim\"", "backend = \"hctl1100\"\n[hctl1100]\nbus = \"sim\"",
                          "backend = \"can\"\n[can_encoder]\nbus = \"sim\""}) {
    const std::string text = std::string("[gyro]\nbackend = \"sim\"\n[encoder]\n") + enc + "\n";
    auto c = parse_config(text, "g.toml");
    ASSERT_TRUE(c) << text << ": " << c.error().message;
    EXPECT_TRUE(simulated_robot(*c));
    EXPECT_TRUE(simulated_gyro(*c));
  }
}

// The drivers' own limits are the rows the config reader checks against (issue 33: they were
// written in both places): a value one beyond the row is refused by the reader at its line and by
// the driver's create() with the same field and range.
void expect_reader_refuses(const char* section, const RangeRow& r) {
  for (double bad : {r.lo - 1.0, r.hi + 1.0}) {
    const std::string text = std::string("[") + section + "]\n" + r.key + " = " +
                             std::to_string(static_cast<long long>(bad)) + "\n";
    auto c = parse_config(text, "bad.toml");
    ASSERT_FALSE(c.ok()) << text;
    char range[64];
    std::snprintf(range, sizeof range, "[%g, %g]", r.lo, r.hi);
    EXPECT_NE(c.error().message.find(std::string("bad.toml:2: ") + section + "." + r.key + " = " +
                                     std::to_string(static_cast<long long>(bad)) +
                                     " is outside the allowed range " + range),
              std::string::npos)
        << c.error().message;
  }
}

void expect_driver_refuses(const Status& s, const std::string& field, const RangeRow& r) {
  ASSERT_FALSE(s);
  ASSERT_TRUE(s.error().range.has_value()) << s.error().message;
  EXPECT_EQ(s.error().range->field, field);
  EXPECT_EQ(s.error().range->lo, r.lo);
  EXPECT_EQ(s.error().range->hi, r.hi);
}

template <class R>
Status status_of(const R& r) {
  if (r) return Ok{};
  return r.error();
}

TEST(ConfigEncoders, DriverLimitsAreTheRowsTheReaderChecks) {
  using namespace drivers;
  expect_reader_refuses("hctl1100", kHctlAgreeWindow);
  expect_reader_refuses("hctl1100", kHctlMaxAttempts);
  expect_reader_refuses("gpio", kGpioBatch);
  expect_reader_refuses("can_encoder", kCanMaxFramesPerRead);
  expect_reader_refuses("can_gyro", kCanMaxFramesPerRead);

  sim::Hctl1100Model left, right;
  sim::SimHctlBus bus(&left, &right);
  Hctl1100Config h;
  h.agree_window = 65;
  expect_driver_refuses(status_of(Hctl1100Encoder::create(bus, h)), "hctl1100: agree_window",
                        kHctlAgreeWindow);
  h = Hctl1100Config{};
  h.max_attempts = 1;
  expect_driver_refuses(status_of(Hctl1100Encoder::create(bus, h)), "hctl1100: max_attempts",
                        kHctlMaxAttempts);
  GpioQuadratureConfig g;
  g.batch = 1025;  // refused before any chip is opened
  expect_driver_refuses(status_of(GpioQuadratureEncoder::open(g)), "gpio: batch", kGpioBatch);
  sim::SimCanPort port;
  CanEncoderConfig ce;
  ce.left = odrive_count_layout(0);
  ce.right = odrive_count_layout(1);
  ce.max_frames_per_read = 0;
  expect_driver_refuses(status_of(CanEncoderSource::create(port, ce)), "max_frames_per_read",
                        kCanMaxFramesPerRead);
  CanGyroConfig cg;
  cg.scale = 1e-3;  // rad/s per LSB: the rest of the config valid
  cg.max_frames_per_read = 4097;
  expect_driver_refuses(status_of(CanGyroSource::create(port, cg)), "CAN gyro: max_frames_per_read",
                        kCanMaxFramesPerRead);
}

}  // namespace
}  // namespace odo::fw
