// The [error_model] config section: defaults, values, range errors naming file, line and field;
// and the shipped odometryd.toml: every key it documents is known and its example in range.
#include <gtest/gtest.h>

#include <cctype>
#include <fstream>
#include <sstream>
#include <string>

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
  EXPECT_EQ(c->error_model.covariance_ticks, 1u);  // default: every tick
  for (const std::uint32_t n : {1u, 10u, 100u}) {  // both ends of the range and a middle
    auto m =
        parse_config("[error_model]\ncovariance_ticks = " + std::to_string(n) + "\n", "x.toml");
    ASSERT_TRUE(m.ok()) << m.error().message;
    EXPECT_EQ(m->error_model.covariance_ticks, n);
  }
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
      // covariance_ticks: whole ticks, 1..kCovarianceTicksMax (100), both ends and a fraction.
      {"[error_model]\ncovariance_ticks = 0\n",
       "bad.toml:2: error_model.covariance_ticks = 0 is outside the allowed range [1, 100]"},
      {"[error_model]\n\ncovariance_ticks = 101\n",
       "bad.toml:3: error_model.covariance_ticks = 101 is outside the allowed range [1, 100]"},
      {"[error_model]\ncovariance_ticks = 2.5\n",
       "bad.toml:2: error_model.covariance_ticks must be an integer"},
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

// uncommented: the shipped file with its commented-out sections ("# [name]" and the "# key = "
// lines under it) turned into real ones, the way a user enables them.
std::string uncommented(const std::string& path) {
  std::ifstream in(path);
  std::ostringstream out;
  std::string line;
  bool in_commented = false;
  while (std::getline(in, line)) {
    const bool section = line.rfind("# [", 0) == 0;
    const bool key = line.size() > 2 && line.rfind("# ", 0) == 0 &&
                     (std::isalpha(static_cast<unsigned char>(line[2])) != 0) &&
                     line.find(" = ") != std::string::npos;
    if (section) in_commented = true;
    if (!section && !key) in_commented = false;
    out << (in_commented ? line.substr(2) : line) << "\n";
  }
  return out.str();
}

TEST(ConfigShipped, EveryDocumentedKeyIsKnownAndItsValueInRange) {
  // README: "The shipped file documents every key". Enabling every commented-out section as
  // written must give a config the reader accepts: no documented key is unknown or misspelt,
  // and every example value is in its range. The sections are only enabled, not selected
  // (encoder.backend stays "sim"), so no device is opened.
  const std::string text = uncommented(ODO_SOURCE_DIR "/firmware/config/odometryd.toml");
  for (const char* section :
       {"[hctl1100]", "[gpio]", "[can_encoder]", "[gyro]", "[can_gyro]", "[resume]", "[selfcal]"}) {
    EXPECT_NE(text.find(std::string("\n") + section), std::string::npos) << section;
  }
  auto c = parse_config(text, "odometryd.toml (uncommented)");
  ASSERT_TRUE(c.ok()) << c.error().message;
  EXPECT_EQ(c->gyro.backend, GyroBackend::kNone);  // the documented default
  EXPECT_EQ(c->can_gyro.id, 0x120);
  EXPECT_EQ(c->selfcal.max_fixes, 41);
}

}  // namespace
}  // namespace odo::fw
