// The UMBmark CSV of `odomctl umbmark compute` (analysis::read_umbmark_runs).
#include <gtest/gtest.h>

#include <sstream>

#include "odo/analysis/umbmark_tools.hpp"

namespace odo::fw {
namespace {

Result<std::vector<calib::UmbmarkRun>> read(const std::string& text) {
  std::istringstream in(text);
  return analysis::read_umbmark_runs(in, "runs.csv");
}

TEST(UmbmarkCsv, ReadsAnyColumnOrderCommentsAndCrlf) {
  auto r = read(
      "# measured 2026-11-22\r\nbumps,etheta,ey,ex,direction\r\n0,0.01,-0.3,0.25,cw\r\n"
      "1,-0.07,0.2,0.1,ccw\r\n0,,0.03,-0.03,ccw\r\n");
  ASSERT_TRUE(r.ok()) << r.error().message;
  ASSERT_EQ(r->size(), 3U);
  EXPECT_EQ((*r)[0].direction, calib::Direction::kCw);
  EXPECT_DOUBLE_EQ((*r)[0].ex, 0.25);
  EXPECT_DOUBLE_EQ((*r)[0].ey, -0.3);
  EXPECT_DOUBLE_EQ(*(*r)[0].etheta, 0.01);
  EXPECT_FALSE((*r)[0].bumps);
  EXPECT_TRUE((*r)[1].bumps);
  EXPECT_EQ((*r)[1].direction, calib::Direction::kCcw);
  EXPECT_FALSE((*r)[2].etheta.has_value());  // empty cell: not measured
}

TEST(UmbmarkCsv, ErrorsNameFileLineAndField) {
  struct Case {
    const char* text;
    const char* message;
  };
  const Case cases[] = {
      {"direction,ex\ncw,0\n", "runs.csv:1: missing column 'ey'"},
      {"direction,ex,ey\ncw,0,0\nright,0,0\n", "runs.csv:3: field 'direction' = 'right'"},
      {"direction,ex,ey\ncw,inf,0\n", "runs.csv:2: field 'ex' = 'inf' is not a finite number"},
      {"direction,ex,ey\ncw,0,1500\n", "runs.csv:2: field 'ey' = 1500 is outside"},
      {"direction,ex,ey,bumps\ncw,0,0,yes\n", "runs.csv:2: field 'bumps' = 'yes' must be 0 or 1"},
      {"direction,ex,ey,bumps\ncw,0,0,1\n", "runs.csv:2: field 'etheta' is required"},
      {"direction,ex,ey\ncw,0\n", "runs.csv:2: expected 3 fields, found 2"},
  };
  for (const Case& c : cases) {
    auto r = read(c.text);
    ASSERT_FALSE(r.ok()) << c.text;
    EXPECT_EQ(r.error().message.rfind(c.message, 0), 0U) << r.error().message;
  }
}

}  // namespace
}  // namespace odo::fw
