#include <gtest/gtest.h>

#include "odo/firmware/config.hpp"
#include "odo/firmware/timing_report.hpp"

namespace odo::fw {
namespace {

// The status line's timing part: "-" for a p99 not summarised yet (count 0: the first 256
// ticks), the max from the first tick; then the summary's p99 in us (35 us = 35000 ns; compute
// 11.3 us = 11300 ns, printed with one decimal).
TEST(TimingStatus, PercentilesAreDashUntilTheFirstSummary) {
  loop::LoopStats st;
  st.wakeup_latency_max = 69'000;
  char buf[96];
  EXPECT_STREQ(format_timing_status(buf, sizeof buf, st), "lat p99/max=-/69 us  cmp p99=- us");
  st.wakeup_latency.count = 256;
  st.wakeup_latency.p99 = 35'000;
  st.compute_time.count = 256;
  st.compute_time.p99 = 11'300;
  EXPECT_STREQ(format_timing_status(buf, sizeof buf, st), "lat p99/max=35/69 us  cmp p99=11.3 us");
}

TEST(RealtimeConfig, DefaultsAndValues) {
  const Config d = default_config();
  EXPECT_EQ(d.realtime.priority, 80);
  EXPECT_TRUE(d.realtime.lock_memory);
  EXPECT_EQ(d.realtime.cpu, -1);
  EXPECT_FALSE(d.realtime.required);
  EXPECT_EQ(d.realtime.cpu_latency_us, -1);  // off: holding it costs power
  auto c = parse_config(
      "[realtime]\npriority = 0\nlock_memory = false\ncpu = 1\nprefault_stack = 0\n"
      "required = true\ncpu_latency_us = 0\n",
      "rt.toml");
  ASSERT_TRUE(c.ok()) << c.error().message;
  EXPECT_EQ(c->realtime.priority, 0);
  EXPECT_FALSE(c->realtime.lock_memory);
  EXPECT_EQ(c->realtime.cpu, 1);
  EXPECT_EQ(c->realtime.prefault_stack, 0);
  EXPECT_TRUE(c->realtime.required);
  EXPECT_EQ(c->realtime.cpu_latency_us, 0);
}

TEST(RealtimeConfig, OutOfRangeAndUnknownKeysNameFileLineAndField) {
  auto c = parse_config("[loop]\nrate_hz = 100\n[realtime]\npriority = 120\n", "rt.toml");
  ASSERT_FALSE(c.ok());
  EXPECT_NE(c.error().message.find("rt.toml:4"), std::string::npos) << c.error().message;
  EXPECT_NE(c.error().message.find("priority"), std::string::npos) << c.error().message;
  EXPECT_NE(c.error().message.find("99"), std::string::npos) << c.error().message;
  auto l = parse_config("[realtime]\ncpu_latency_us = -2\n", "rt.toml");
  ASSERT_FALSE(l.ok());
  EXPECT_NE(l.error().message.find("rt.toml:2"), std::string::npos) << l.error().message;
  EXPECT_NE(l.error().message.find("cpu_latency_us"), std::string::npos) << l.error().message;
  EXPECT_NE(l.error().message.find("1000000"), std::string::npos) << l.error().message;
  auto u = parse_config("[realtime]\nprio = 10\n", "rt.toml");
  ASSERT_FALSE(u.ok());
  EXPECT_NE(u.error().message.find("prio"), std::string::npos) << u.error().message;
  auto b = parse_config("[realtime]\nrequired = \"yes\"\n", "rt.toml");
  ASSERT_FALSE(b.ok());
  EXPECT_NE(b.error().message.find("required"), std::string::npos) << b.error().message;
}

}  // namespace
}  // namespace odo::fw
