// Fault matrix, "config with each kind of error": every kind of mistake a config file can hold is
// rejected with a message naming the file, the line, the field and what was expected, and every
// numeric setting is checked at both ends of its documented range (README, configuration
// reference). The daemon turns each of these into exit status 2 (tests/cli/test_cli.sh).
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "odo/firmware/config.hpp"
#include "odo/hal/field_range.hpp"
#include "odo/odometry/gyrodometry.hpp"

namespace odo::fw {
namespace {

struct NumericKey {
  const char* table;
  const char* key;
  const char* below;  // TOML literal just below the range
  const char* above;  // just above
  const char* range;  // as printed in the message
};

// Every numeric setting with its documented range (README "Configuration reference").
constexpr NumericKey kNumeric[] = {
    {"loop", "rate_hz", "49.9", "2000.5", "[50, 2000] Hz"},
    {"loop", "status_period", "-0.1", "3601", "[0, 3600] s"},
    {"robot", "wheel_diameter", "0.004", "5.1", "[0.005, 5] m"},
    {"robot", "counts_per_rev", "0.5", "2e9", "[1, 1e+09] counts"},
    {"robot", "gear_ratio", "0.0009", "10001", "[0.001, 10000]"},
    {"robot", "wheelbase", "0.009", "20.5", "[0.01, 20] m"},
    {"robot", "c_l", "0.49", "1.51", "[0.5, 1.5]"},
    {"robot", "c_r", "0.49", "1.51", "[0.5, 1.5]"},
    {"robot", "x_icr", "-2.1", "2.1", "[-2, 2] m"},
    {"sim", "side", "0.09", "100.1", "[0.1, 100] m"},
    {"sim", "speed", "0.009", "5.1", "[0.01, 5] m/s"},
    {"sim", "turn_rate", "0.04", "10.1", "[0.05, 10] rad/s"},
    {"sim", "pause", "-1", "61", "[0, 60] s"},
    {"can", "pose_hz", "-0.1", "2000.5", "[0, 2000] Hz"},
    {"can", "velocity_hz", "-0.1", "2000.5", "[0, 2000] Hz"},
    {"can", "uncertainty_hz", "-0.1", "2000.5", "[0, 2000] Hz"},
    {"can", "status_hz", "-0.1", "2000.5", "[0, 2000] Hz"},
    {"can", "timing_hz", "-0.1", "2000.5", "[0, 2000] Hz"},
    {"can", "reopen_period", "0.009", "60.1", "[0.01, 60] s"},
    {"can_encoder", "timeout", "0.004", "10.5", "[0.005, 10] s"},
    {"can_encoder", "max_speed", "0.009", "100.5", "[0.01, 100] m/s"},
    {"can_encoder", "request_rate", "-0.5", "1000.5", "[0, 1000] Hz"},
    {"can_encoder", "sim_period", "0.0009", "1.5", "[0.001, 1] s"},
    {"can_encoder", "sim_stop_left_after", "-1.5", "2e6", "[-1, 1e+06] s"},
    {"can_encoder", "sim_stop_right_after", "-1.5", "2e6", "[-1, 1e+06] s"},
};

std::string doc(const NumericKey& k, const char* value) {
  // The value sits on line 3 so that the line number in the message is checked too.
  return std::string("# test\n[") + k.table + "]\n" + k.key + " = " + value + "\n";
}

void expect_error(const std::string& text, const std::string& expect) {
  auto c = parse_config(text, "bad.toml");
  ASSERT_FALSE(c.ok()) << text;
  EXPECT_NE(c.error().message.find(expect), std::string::npos)
      << "message: " << c.error().message << "\nexpected: " << expect;
}

TEST(ConfigErrors, EveryNumberBelowItsRange) {
  for (const auto& k : kNumeric) {
    expect_error(doc(k, k.below), std::string("bad.toml:3: ") + k.table + "." + k.key + " = " +
                                      k.below + " is outside the allowed range " + k.range);
  }
}

TEST(ConfigErrors, EveryNumberAboveItsRange) {
  for (const auto& k : kNumeric) {
    // 2e9 prints as 2e+09: compare up to the value.
    expect_error(doc(k, k.above), std::string("bad.toml:3: ") + k.table + "." + k.key + " = ");
    expect_error(doc(k, k.above), std::string("is outside the allowed range ") + k.range);
  }
}

TEST(ConfigErrors, EveryNumberRejectsNanInfAndText) {
  for (const auto& k : kNumeric) {
    const std::string field = std::string("bad.toml:3: ") + k.table + "." + k.key;
    expect_error(doc(k, "nan"), field + " = nan is outside the allowed range");
    expect_error(doc(k, "inf"), field + " = inf is outside the allowed range");
    expect_error(doc(k, "-inf"), field + " = -inf is outside the allowed range");
    expect_error(doc(k, "\"1.0\""), field + " must be a number");
    expect_error(doc(k, "true"), field + " must be a number");
    expect_error(doc(k, "[1.0]"), field + " must be a number");
    expect_error(doc(k, "1979-05-27"), field + " must be a number");
  }
}

TEST(ConfigErrors, IntegerSettingRejectsFractionsAndRange) {
  expect_error("[sim]\n\ncounter_bits = 32.0\n", "bad.toml:3: sim.counter_bits must be an integer");
  expect_error("[sim]\ncounter_bits = 15\n",
               "bad.toml:2: sim.counter_bits = 15 is outside the allowed range [16, 64]");
  expect_error("[sim]\ncounter_bits = 65\n",
               "bad.toml:2: sim.counter_bits = 65 is outside the allowed range [16, 64]");
  expect_error("[sim]\ncounter_bits = \"32\"\n", "bad.toml:2: sim.counter_bits must be an integer");
}

TEST(ConfigErrors, ChoicesNameTheAllowedWords) {
  expect_error("[encoder]\nbackend = \"Sim\"\n",
               "bad.toml:2: encoder.backend = \"Sim\" is not one of: sim, hctl1100, gpio, can");
  expect_error("[encoder]\nbackend = 1\n", "bad.toml:2: encoder.backend must be a string");
  expect_error("[sim]\nrobot = \"labmate2\"\n",
               "bad.toml:2: sim.robot = \"labmate2\" is not one of: labmate, nominal");
  expect_error("[sim]\nscenario = \"circle\"\n",
               "bad.toml:2: sim.scenario = \"circle\" is not one of: square-ccw, square-cw, "
               "squares, idle");
}

// [can]: integers, choices, the interface name, addressing and rates that must divide the loop.
TEST(ConfigErrors, CanSection) {
  expect_error("[can]\nnode_id = 64\n",
               "bad.toml:2: can.node_id = 64 is outside the allowed range [0, 63]");
  expect_error("[can]\nnode_id = -1\n",
               "bad.toml:2: can.node_id = -1 is outside the allowed range [0, 63]");
  expect_error("[can]\nnode_id = 1.5\n", "bad.toml:2: can.node_id must be an integer");
  expect_error("[can]\nbase_id = 1040\n",
               "bad.toml:2: can.base_id = 1040 is outside the allowed range [0, 1024]");
  expect_error("[can]\nbase_id = -16\n",
               "bad.toml:2: can.base_id = -16 is outside the allowed range [0, 1024]");
  expect_error("[can]\nbase_id = 1032\n", "bad.toml:2: can.base_id = 1032 is outside");
  expect_error("[can]\n\nbase_id = 520\n",
               "bad.toml:3: can.base_id = 520 must be a multiple of 16");
  expect_error("[can]\nbus = \"slcan\"\n",
               "bad.toml:2: can.bus = \"slcan\" is not one of: sim, socketcan, none");
  expect_error("[can]\ninterface = \"\"\n", "bad.toml:2: can.interface = \"\" must be 1..15");
  expect_error("[can]\ninterface = \"a_very_long_name0\"\n",
               "bad.toml:2: can.interface = \"a_very_long_name0\" must be 1..15 characters");
  expect_error("[can]\nset_pose = 1\n", "bad.toml:2: can.set_pose must be true or false");
  // Rates: 0 (off) or the loop rate divided by a whole number.
  expect_error("[can]\npose_hz = 30\n",
               "bad.toml:2: can.pose_hz = 30 Hz must be 0 or loop.rate_hz / n for a whole n >= 1 "
               "(loop.rate_hz = 100)");
  expect_error("[loop]\nrate_hz = 200\n[can]\nstatus_hz = 300\n",
               "bad.toml:4: can.status_hz = 300 Hz must be 0 or loop.rate_hz / n");
  // A rate left at its default (pose_hz 50) that the loop rate the user wrote cannot give: the
  // key written (loop.rate_hz, line 2) is blamed, not the default the user never wrote (issue 35).
  expect_error("[loop]\nrate_hz = 100.5\n",
               "bad.toml:2: loop.rate_hz = 100.5 Hz is not a whole multiple of can.pose_hz = 50 Hz "
               "(its default)");
  expect_error("[loop]\nrate_hz = 125\n[can]\npose_hz = 25\n",
               "bad.toml:2: loop.rate_hz = 125 Hz is not a whole multiple of can.velocity_hz = 50 "
               "Hz (its default)");
  for (const char* ok : {"[can]\npose_hz = 0\n", "[can]\npose_hz = 100\n",
                         "[loop]\nrate_hz = 200\n[can]\npose_hz = 40\ntiming_hz = 0.5\n",
                         "[can]\nbus = \"none\"\n", "[can]\nbase_id = 0\nnode_id = 63\n"}) {
    EXPECT_TRUE(parse_config(ok, "ok.toml").ok()) << ok;
  }
}

TEST(ConfigErrors, UnknownKeysAndTablesEverywhere) {
  for (const char* table : {"loop", "robot", "encoder", "sim", "realtime", "calibration",
                            "hctl1100", "gpio", "can_encoder", "error_model", "can"}) {
    expect_error(std::string("[") + table + "]\n\nbogus = 1\n",
                 std::string("bad.toml:3: ") + table + ".bogus is not a known setting (misspelt?)");
  }
  expect_error("rate_hz = 100\n", "bad.toml:1: rate_hz is not a known setting");
  expect_error("[calibraton]\nstore = \"\"\n", "calibraton is not a known setting");
  expect_error("[calibration]\nc_l = 1.0\n", "bad.toml:2: calibration.c_l is not a known setting");
  expect_error("[loop.sub]\nx = 1\n", "loop.sub is not a known setting");
}

TEST(ConfigErrors, SectionOfTheWrongShape) {
  expect_error("loop = 3\n", "bad.toml:1: loop must be a table");
  expect_error("robot = [1, 2]\n", "bad.toml:1: robot must be a table");
  expect_error("[[sim]]\nside = 1.0\n", "sim must be a table");
}

TEST(ConfigErrors, TomlSyntaxErrorsNameTheLine) {
  expect_error("[loop]\nrate_hz = \n", "bad.toml:2: TOML syntax error");
  expect_error("[loop]\nrate_hz = 100\nrate_hz = 200\n", "bad.toml:3: TOML syntax error");
  expect_error("[loop]\n[loop]\n", "bad.toml:2: TOML syntax error");
  expect_error("[sim]\nscenario = \"squares\n", "bad.toml:2: TOML syntax error");
  expect_error("\n\n[robot\n", "bad.toml:3: TOML syntax error");
  expect_error("[loop]\nrate_hz = 1_00_\n", "bad.toml:2: TOML syntax error");
  expect_error(std::string("[loop]\nrate_hz = 100\x00\n", 22), "bad.toml:2: TOML syntax error");
}

TEST(ConfigErrors, NonAsciiNeverReachesTheTomlParser) {
  // Regression (fuzz_config): U+2EFF (UTF-8 e2 bb bf) before a key made toml++ 3.3 reach
  // __builtin_unreachable() (undefined behaviour; upstream issues #190, #295), as do U+00A7
  // after a line-ending backslash and other characters. Any byte >= 0x80 is refused with its
  // position before parsing ("rate_hz = 100 # caf" is 19 characters, the e-acute is column 20).
  expect_error(
      "\xe2\xbb\xbfl8np = {wh=\"idle\"",
      "bad.toml:1: column 1: byte 0xE2 is not ASCII (the config file must be plain ASCII)");
  expect_error("[sim]\nscenario = \"\"\"\\\n\xc2\xa7\"\"\"\n", "bad.toml:3: column 1: byte 0xC2");
  expect_error("[loop]\nrate_hz = 100 # caf\xe9\n",
               "bad.toml:2: column 20: byte 0xE9 is not ASCII");
}

TEST(ConfigErrors, FirstErrorWinsAndNothingIsHalfApplied) {
  // Two mistakes: the first (line 2) is reported; no Config comes back at all, so nothing of a
  // bad file can reach the loop.
  auto c = parse_config("[loop]\nrate_hz = 1\n[robot]\nwheelbase = 99\n", "bad.toml");
  ASSERT_FALSE(c.ok());
  EXPECT_NE(c.error().message.find("bad.toml:2: loop.rate_hz"), std::string::npos)
      << c.error().message;
}

TEST(ConfigErrors, FileMissingOrUnreadable) {
  auto missing = load_config("/nonexistent/odometryd.toml");
  ASSERT_FALSE(missing.ok());
  EXPECT_EQ(missing.error().message,
            "/nonexistent/odometryd.toml: cannot open config file (No such file or directory)");
  // A directory opens but cannot be read: an error, not an empty file meaning "all defaults"
  // (it was the latter before this test).
  const auto dir = std::filesystem::temp_directory_path() /
                   ("odo_cfg_dir_" + std::to_string(::getpid()) + ".toml");
  std::filesystem::create_directory(dir);
  auto d = load_config(dir.string());
  std::filesystem::remove(dir);
  ASSERT_FALSE(d.ok());
  EXPECT_EQ(d.error().message, dir.string() + ": cannot read config file (Is a directory)");
}

// shortest: v as the fewest significant digits (at least 6) that read back as v: both the TOML
// literal a test writes and the number the message prints, so the two are the same text.
std::string shortest(double v) {
  char b[32];
  for (int p = 6; p <= 17; ++p) {
    std::snprintf(b, sizeof b, "%.*g", p, v);
    if (std::strtod(b, nullptr) == v) break;
  }
  return b;
}

// A number key of a range table, at its limits: the limit itself is taken (unless the range is
// open there), a step of 1e-9 (relative) beyond it is refused with file, line, section.key and
// the range as the table states it.
void expect_boundaries(const std::string& table, const RangeRow& r) {
  const auto doc_of = [&](double v) {
    return "# test\n[" + table + "]\n" + r.key + " = " + shortest(v) + "\n";
  };
  const auto step = [](double x) { return 1e-9 * std::max(1.0, std::abs(x)); };
  const std::string unit = *r.unit != '\0' ? std::string(" ") + r.unit : std::string();
  const std::string range =
      std::string(r.lo_open ? "(" : "[") + shortest(r.lo) + ", " + shortest(r.hi) + "]" + unit;
  const double below = r.lo_open ? r.lo : r.lo - step(r.lo), above = r.hi + step(r.hi);
  for (double bad : {below, above})
    expect_error(doc_of(bad), "bad.toml:3: " + table + "." + r.key + " = " + shortest(bad) +
                                  " is outside the allowed range " + range);
  for (double good : {r.lo_open ? r.lo + step(r.lo) : r.lo, r.hi}) {
    auto c = parse_config(doc_of(good), "bad.toml");
    EXPECT_TRUE(c.ok()) << doc_of(good) << (c.ok() ? "" : c.error().message);
  }
}

// [gyro]: the fusion's numbers from its own table (gyrodometry_range at the default loop rate and
// still_time, as a file that sets only that key sees them), the source's from config.hpp.
TEST(ConfigErrors, GyroEveryNumberAtBothLimitsFromTheFusionsTable) {
  const Config def = default_config();
  for (std::size_t i = 0; i < kGyroConfigParams; ++i)
    expect_boundaries("gyro", gyrodometry_range(static_cast<GyroParam>(i), 1.0 / def.loop.rate_hz,
                                                def.gyro.still_time));
  for (const auto& n : kGyroSourceNumbers) expect_boundaries("gyro", n.row);
}

// [serial]: every number of its table (config.hpp, kSerialNumbers).
TEST(ConfigErrors, SerialEveryNumberAtBothLimitsFromItsTable) {
  for (const auto& n : kSerialNumbers) expect_boundaries("serial", n.row);
}

// [selfcal]: every number of its table (config.hpp, kSelfCalNumbers / kSelfCalIntegers).
TEST(ConfigErrors, SelfCalEveryNumberAtBothLimitsFromItsTable) {
  for (const auto& r : kSelfCalNumbers) expect_boundaries("selfcal", {r.key, r.lo, r.hi, r.unit});
  for (const auto& r : kSelfCalIntegers) {
    const auto doc_of = [&](int v) {
      return std::string("# test\n[selfcal]\n") + r.key + " = " + std::to_string(v) + "\n";
    };
    for (int bad : {r.lo - 1, r.hi + 1})
      expect_error(doc_of(bad), std::string("bad.toml:3: selfcal.") + r.key + " = " +
                                    std::to_string(bad) + " is outside the allowed range [" +
                                    std::to_string(r.lo) + ", " + std::to_string(r.hi) + "]");
  }
}

// The case a user met (issue 33): at 100 Hz a window of 1.5 ticks passed the reader's own range
// [0.01, 10] and failed later in the fusion under another name and range. Now one table: the
// reader refuses it at its line with the fusion's range (two ticks = 0.02 s at 100 Hz), and the
// fusion, given the same value, reports the same field and range.
TEST(ConfigErrors, GyroWindowOfOneAndAHalfTicksIsRefusedOnceWithTheFusionsRange) {
  expect_error("[loop]\nrate_hz = 100\n[gyro]\nbackend = \"sim\"\nwindow = 0.015\n",
               "bad.toml:5: gyro.window = 0.015 is outside the allowed range [0.02, 10] s");
  GyrodometryParams p;
  p.tick = 0.01;
  p.window = 0.015;
  const Status s = check_gyrodometry(p);
  ASSERT_FALSE(s);
  ASSERT_TRUE(s.error().range.has_value());
  EXPECT_EQ(s.error().range->field, "window");
  EXPECT_EQ(s.error().range->lo, 0.02);
  EXPECT_EQ(s.error().range->hi, 10.0);
  expect_error("[loop]\nrate_hz = 100\n[gyro]\nwindow = 0.02\nbias_tau = 0.4\n",
               "bad.toml:5: gyro.bias_tau = 0.4 is outside the allowed range [0.5, 86400] s");
}

// [encoder]'s several-wheels numbers from the combiner's own table (side_wheels_range at the
// default loop rate: slip_window from one tick, 0.01 s, to 128 ticks); wheels_per_side, a whole
// number, at its limits; several wheels with a backend that reads one counter per side refused.
TEST(ConfigErrors, EncoderSideWheelsNumbersFromTheCombinersTable) {
  const Config def = default_config();
  for (std::size_t i = 1; i < kSideConfigParams; ++i)
    expect_boundaries("encoder",
                      side_wheels_range(static_cast<SideParam>(i), 1.0 / def.loop.rate_hz));
  expect_error("[encoder]\nwheels_per_side = 5\n",
               "bad.toml:2: encoder.wheels_per_side = 5 is outside the allowed range [1, 4]");
  expect_error("[encoder]\nwheels_per_side = 0\n",
               "bad.toml:2: encoder.wheels_per_side = 0 is outside the allowed range [1, 4]");
  expect_error("[encoder]\nbackend = \"hctl1100\"\nwheels_per_side = 2\n",
               "bad.toml:3: encoder.wheels_per_side = 2 needs a backend that reads several "
               "counters per side; backend \"hctl1100\" reads one");
  expect_error("[encoder]\ncombine = \"max\"\n", "encoder.combine");
  auto c = parse_config("[encoder]\nwheels_per_side = 4\ncombine = \"median\"\n", "ok.toml");
  ASSERT_TRUE(c.ok()) << c.error().message;
  EXPECT_EQ(c->encoder.side.wheels_per_side, 4);
  EXPECT_EQ(c->encoder.side.combine, SideCombine::kMedian);
  EXPECT_DOUBLE_EQ(c->encoder.side.read_period, 0.01);
}

// RangeText: the "lo..hi" of a config comment, "(lo..hi]" when open at lo; lo may be a word
// ("2 ticks", "still_time"). Empty lo: none found.
struct RangeText {
  std::string lo, hi;
  bool open = false;
};
RangeText range_text_of(const std::string& c) {
  RangeText r;
  const std::size_t dots = c.find("..");
  if (dots == std::string::npos) return r;
  const auto num = [](char ch) {
    return std::isdigit(static_cast<unsigned char>(ch)) || ch == '.' || ch == 'e' || ch == 'E' ||
           ch == '+' || ch == '-';
  };
  std::size_t b = dots;
  for (const char* word : {"2 ticks", "still_time"})
    if (dots >= std::strlen(word) &&
        c.compare(dots - std::strlen(word), std::strlen(word), word) == 0)
      b = dots - std::strlen(word);
  if (b == dots)
    while (b > 0 && num(c[b - 1])) --b;
  std::size_t e = dots + 2;
  while (e < c.size() && num(c[e])) ++e;
  r.lo = c.substr(b, dots - b);
  r.hi = c.substr(dots + 2, e - dots - 2);
  r.open = b > 0 && c[b - 1] == '(' && e < c.size() && c[e] == ']';
  return r;
}

// The shipped config's commented [gyro] and [selfcal] keys state each range as its table does:
// "lo..hi", "(lo..hi]" where lo itself is refused (numbers compared as numbers: 1e-6 = 1e-06);
// window's lower limit is "2 ticks" and bias_tau's "still_time" (they follow other settings).
TEST(ConfigErrors, ShippedConfigCommentsStateTheTablesRanges) {
  std::ifstream f(std::string(ODO_SOURCE_DIR) + "/firmware/config/odometryd.toml");
  ASSERT_TRUE(f) << "cannot read the shipped config";
  std::vector<std::string> lines;
  for (std::string l; std::getline(f, l);) lines.push_back(l);
  const auto expect_comment = [&](const std::string& key, const std::string& lo, double hi,
                                  bool lo_open) {
    const std::string head = "# " + key + " = ";
    const auto it = std::find_if(lines.begin(), lines.end(),
                                 [&](const std::string& l) { return l.rfind(head, 0) == 0; });
    ASSERT_NE(it, lines.end()) << "no commented line for " << key;
    const std::string comment = it->substr(it->find('#', 1));
    const RangeText t = range_text_of(comment);
    ASSERT_FALSE(t.lo.empty()) << *it;
    EXPECT_EQ(t.open, lo_open) << *it;
    if (lo == "2 ticks" || lo == "still_time")
      EXPECT_EQ(t.lo, lo) << *it;
    else
      EXPECT_EQ(std::strtod(t.lo.c_str(), nullptr), std::strtod(lo.c_str(), nullptr)) << *it;
    EXPECT_EQ(std::strtod(t.hi.c_str(), nullptr), hi) << *it;
  };
  for (std::size_t i = 0; i < kGyroConfigParams; ++i) {
    const auto k = static_cast<GyroParam>(i);
    const RangeRow r = gyrodometry_range(k, 0.01, 0.5);
    const std::string lo = k == GyroParam::kWindow    ? "2 ticks"
                           : k == GyroParam::kBiasTau ? "still_time"
                                                      : shortest(r.lo);
    expect_comment(r.key, lo, r.hi, r.lo_open);
  }
  for (const auto& r : kSelfCalNumbers) expect_comment(r.key, shortest(r.lo), r.hi, false);
  for (const auto& r : kSelfCalIntegers)
    expect_comment(r.key, std::to_string(r.lo), static_cast<double>(r.hi), false);
}

}  // namespace
}  // namespace odo::fw
