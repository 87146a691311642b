#include <gtest/gtest.h>

#include "odo/firmware/config.hpp"

namespace odo::fw {
namespace {

TEST(Config, EmptyTextGivesDefaults) {
  auto c = parse_config("", "empty.toml");
  ASSERT_TRUE(c.ok()) << c.error().message;
  EXPECT_DOUBLE_EQ(c->loop.rate_hz, 100.0);
  EXPECT_EQ(c->encoder.backend, EncoderKind::kSim);
  EXPECT_DOUBLE_EQ(c->robot.wheelbase, 0.34);
}

TEST(Config, ReadsValues) {
  auto c = parse_config(R"(
[loop]
rate_hz = 500
[robot]
wheel_diameter = 0.1
counts_per_rev = 4096
wheelbase = 0.25
[sim]
scenario = "square-cw"
counter_bits = 16
start_delay = 1.5
)",
                        "x.toml");
  ASSERT_TRUE(c.ok()) << c.error().message;
  EXPECT_DOUBLE_EQ(c->loop.rate_hz, 500.0);
  EXPECT_DOUBLE_EQ(c->robot.wheel_diameter, 0.1);
  EXPECT_DOUBLE_EQ(c->robot.counts_per_rev, 4096);
  EXPECT_DOUBLE_EQ(c->robot.wheelbase, 0.25);
  EXPECT_DOUBLE_EQ(c->robot.wheelbase_nominal, 0.25);
  EXPECT_EQ(c->sim.scenario, SimScenario::kSquareCw);
  EXPECT_EQ(c->sim.counter_bits, 16);
  EXPECT_DOUBLE_EQ(c->sim.start_delay, 1.5);
}

struct BadConfig {
  const char* text;
  const char* expect;  // substring of the message: file:line and field
};

class ConfigRejects : public ::testing::TestWithParam<BadConfig> {};

TEST_P(ConfigRejects, NamesFileLineFieldAndRange) {
  auto c = parse_config(GetParam().text, "bad.toml");
  ASSERT_FALSE(c.ok());
  EXPECT_NE(c.error().message.find(GetParam().expect), std::string::npos) << c.error().message;
}

INSTANTIATE_TEST_SUITE_P(
    Cases, ConfigRejects,
    ::testing::Values(
        BadConfig{"[loop]\nrate_hz = 5000\n",
                  "bad.toml:2: loop.rate_hz = 5000 is outside the allowed range [50, 2000] Hz"},
        BadConfig{"[robot]\n\nwheelbase = 340\n", "bad.toml:3: robot.wheelbase = 340 is outside"},
        BadConfig{"[robot]\nwheel_diameter = \"big\"\n",
                  "bad.toml:2: robot.wheel_diameter must be a number"},
        BadConfig{"[loop]\nrate = 100\n", "bad.toml:2: loop.rate is not a known setting"},
        BadConfig{"[encoder]\nbackend = \"usb\"\n",
                  "encoder.backend = \"usb\" is not one of: sim, hctl1100, gpio, can"},
        BadConfig{"[sim]\ncounter_bits = 8\n",
                  "sim.counter_bits = 8 is outside the allowed range [16, 64]"},
        BadConfig{"[sim]\nstart_delay = -1\n",
                  "bad.toml:2: sim.start_delay = -1 is outside the allowed range [0, 600] s"},
        BadConfig{"[loop\n", "bad.toml:1: TOML syntax error"},
        BadConfig{"loop = 3\n", "bad.toml:1: loop must be a table"},
        BadConfig{"[robott]\n", "robott is not a known setting"}));

TEST(Config, MissingFileIsNamed) {
  auto c = load_config("/nonexistent/odometryd.toml");
  ASSERT_FALSE(c.ok());
  EXPECT_NE(c.error().message.find("/nonexistent/odometryd.toml"), std::string::npos);
}

}  // namespace
}  // namespace odo::fw
