// The [error_model] config section: defaults, values, range errors naming file, line and field.
#include <gtest/gtest.h>

#include "odo/firmware/config.hpp"

namespace odo::fw {
namespace {

TEST(ConfigErrorModel, DefaultsAreThePapersValues) {
  // Chong & Kleeman Sec. 5.2: k_L = 0.00040, k_R = 0.00058 m^(1/2).
  auto c = parse_config("", "empty.toml");
  ASSERT_TRUE(c.ok()) << c.error().message;
  EXPECT_DOUBLE_EQ(c->error_model.k_left, 0.00040);
  EXPECT_DOUBLE_EQ(c->error_model.k_right, 0.00058);
}

TEST(ConfigErrorModel, ReadsValues) {
  auto c = parse_config("[error_model]\nk_left = 0.001\nk_right = 0\n", "x.toml");
  ASSERT_TRUE(c.ok()) << c.error().message;
  EXPECT_DOUBLE_EQ(c->error_model.k_left, 0.001);
  EXPECT_DOUBLE_EQ(c->error_model.k_right, 0.0);
}

TEST(ConfigErrorModel, RejectsOutOfRangeAndUnknownKeys) {
  struct Bad {
    const char* text;
    const char* expect;
  };
  const Bad cases[] = {
      {"[error_model]\nk_left = -0.0004\n",
       "bad.toml:2: error_model.k_left = -0.0004 is outside the allowed range [0, 0.1] m^(1/2)"},
      {"[error_model]\n\nk_right = 0.58\n", "bad.toml:3: error_model.k_right = 0.58 is outside"},
      {"[error_model]\nk_right = \"small\"\n", "bad.toml:2: error_model.k_right must be a number"},
      {"[error_model]\nk = 0.1\n", "bad.toml:2: error_model.k is not a known setting"},
  };
  for (const Bad& b : cases) {
    auto c = parse_config(b.text, "bad.toml");
    ASSERT_FALSE(c.ok()) << b.text;
    EXPECT_NE(c.error().message.find(b.expect), std::string::npos) << c.error().message;
  }
}

TEST(ConfigErrorModel, ShippedFileParses) {
  auto c = load_config(ODO_SOURCE_DIR "/firmware/config/odometryd.toml");
  ASSERT_TRUE(c.ok()) << c.error().message;
  EXPECT_DOUBLE_EQ(c->error_model.k_left, 0.00040);
  EXPECT_DOUBLE_EQ(c->error_model.k_right, 0.00058);
}

}  // namespace
}  // namespace odo::fw
