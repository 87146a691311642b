// Config sections [hctl1100] and [gpio] (issue 5): values, defaults, and clear errors.
#include <gtest/gtest.h>

#include "odo/firmware/config.hpp"

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
  EXPECT_EQ(c->encoder.backend, "hctl1100");
  const Hctl1100Section& h = c->hctl1100;
  EXPECT_EQ(h.bus, "gpio");
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
        Bad{"[gpio]\nleft_c = 1\n", "bad.toml:2: gpio.left_c is not a known setting"}));

}  // namespace
}  // namespace odo::fw
