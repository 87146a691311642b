// [ros2] in odometryd.toml (issue 19): read in every build (with -DODO_ROS2=OFF too), its ranges
// and name rules the ros2 library's (odo/ros2/config.hpp), errors naming file, line, field and
// what was expected, as for every other table; enabled = true is an error in a build without DDS.
#include <gtest/gtest.h>

#include <string>

#include "odo/firmware/config.hpp"
#include "odo/ros2/config.hpp"

namespace odo::fw {
namespace {

// error_of: the message parsing `body` (placed at line 3 of the file) gives; "" if it parses.
std::string error_of(const std::string& body) {
  auto c = parse_config("# ros2 test\n[ros2]\n" + body + "\n", "r.toml");
  return c.ok() ? "" : c.error().message;
}

TEST(ConfigRos2, DefaultsAreOffWithTheRos2Names) {
  auto c = parse_config("", "empty.toml");
  ASSERT_TRUE(c.ok()) << c.error().message;
  ASSERT_NE(c->ros2, nullptr);
  EXPECT_FALSE(c->ros2->enabled);
  EXPECT_EQ(c->ros2->domain_id, 0u);
  EXPECT_EQ(c->ros2->odom_frame, "odom");
  EXPECT_EQ(c->ros2->base_frame, "base_link");
  EXPECT_TRUE(c->ros2->publish_tf);
  EXPECT_TRUE(c->ros2->multicast);
  EXPECT_EQ(c->ros2->spin_us, 0);  // the early wake-up is off unless asked for
}

TEST(ConfigRos2, EveryKeyIsRead) {
  auto c = parse_config(
      "[loop]\nrate_hz = 200\n[ros2]\ndomain_id = 232\nnamespace = \"/robot1\"\n"
      "odom_frame = \"odom1\"\nbase_frame = \"base_footprint\"\nrate_hz = 200\n"
      "publish_tf = false\ninterfaces = [\"eth0\", \"lo\"]\npeers = [\"192.168.1.20\"]\n"
      "multicast = false\npriority = 40\nspin_us = 300\n",
      "all.toml");
  ASSERT_TRUE(c.ok()) << c.error().message;
  const ros2::Config& r = *c->ros2;
  EXPECT_EQ(r.domain_id, 232u);
  EXPECT_EQ(r.ns, "/robot1");
  EXPECT_EQ(r.odom_frame, "odom1");
  EXPECT_EQ(r.base_frame, "base_footprint");
  EXPECT_EQ(r.rate_hz, 200.0);
  EXPECT_FALSE(r.publish_tf);
  EXPECT_EQ(r.interfaces, (std::vector<std::string>{"eth0", "lo"}));
  EXPECT_EQ(r.peers, (std::vector<std::string>{"192.168.1.20"}));
  EXPECT_FALSE(r.multicast);
  EXPECT_EQ(r.priority, 40);
  EXPECT_EQ(r.spin_us, 300);
}

TEST(ConfigRos2, ErrorsNameFileLineFieldAndRange) {
  // domain id: RTPS port mapping, 0..kDomainIdMax (232).
  EXPECT_EQ(error_of("domain_id = 233"),
            "r.toml:3: ros2.domain_id = 233 is outside the allowed range [0, 232]");
  EXPECT_EQ(error_of("domain_id = -1"),
            "r.toml:3: ros2.domain_id = -1 is outside the allowed range [0, 232]");
  // rate: kRateMinHz (0.1) up to the loop rate (default 100 Hz).
  EXPECT_EQ(error_of("rate_hz = 101"),
            "r.toml:3: ros2.rate_hz = 101 is outside the allowed range [0.1, 100] Hz");
  EXPECT_EQ(error_of("rate_hz = 0.05"),
            "r.toml:3: ros2.rate_hz = 0.05 is outside the allowed range [0.1, 100] Hz");
  EXPECT_EQ(error_of("odom_frame = \"/odom\""),
            "r.toml:3: ros2.odom_frame = \"/odom\" must not start with '/' (a tf2 frame id)");
  EXPECT_EQ(error_of("base_frame = \"odom\""),
            "r.toml:3: ros2.base_frame = \"odom\" must differ from odom_frame");
  EXPECT_EQ(error_of("namespace = \"robot\""),
            "r.toml:3: ros2.namespace = \"robot\" must start with '/' (\"\" or \"/name\")");
  EXPECT_EQ(error_of("interfaces = \"eth0\""),
            "r.toml:3: ros2.interfaces must be an array of strings, e.g. [\"eth0\"]");
  EXPECT_EQ(error_of("peers = [1]"),
            "r.toml:3: ros2.peers must be an array of strings, e.g. [\"eth0\"]");
  // Without multicast the peers are the only discovery: reported at the table (no peers line).
  EXPECT_EQ(error_of("multicast = false"),
            "r.toml:2: ros2.peers must name at least one peer when multicast = false "
            "(nothing to discover)");
  // The publish thread's SCHED_FIFO priority: 0..98, and below the loop's (default 80).
  EXPECT_EQ(error_of("priority = 99"),
            "r.toml:3: ros2.priority = 99 is outside the allowed range [0, 98]");
  EXPECT_EQ(error_of("priority = 80"),
            "r.toml:3: ros2.priority = 80 must be below realtime.priority (80): the publish "
            "thread must never preempt the loop");
  EXPECT_EQ(error_of("priority = 79"), "");
  auto no_rt = parse_config("[realtime]\npriority = 0\n[ros2]\npriority = 90\n", "n.toml");
  ASSERT_TRUE(no_rt.ok()) << no_rt.error().message;  // a loop without SCHED_FIFO: any priority
  EXPECT_EQ(no_rt->ros2->priority, 90);
  // The early wake-up: 0..2000 us (kSpinMaxUs), and at most half the publish period.
  EXPECT_EQ(error_of("spin_us = 2001"),
            "r.toml:3: ros2.spin_us = 2001 is outside the allowed range [0, 2000]");
  EXPECT_EQ(error_of("spin_us = -1"),
            "r.toml:3: ros2.spin_us = -1 is outside the allowed range [0, 2000]");
  EXPECT_EQ(error_of("spin_us = 2000"), "");
  auto fast =
      parse_config("[loop]\nrate_hz = 1000\n[ros2]\nrate_hz = 1000\nspin_us = 501\n", "f.toml");
  ASSERT_FALSE(fast.ok());
  EXPECT_EQ(fast.error().message,
            "f.toml:5: ros2.spin_us = 501 us is outside [0, 500] (at most 2000 us and half the "
            "publish period)");
  EXPECT_EQ(error_of("domian_id = 3"),
            "r.toml:3: ros2.domian_id is not a known setting (misspelt?)");
}

TEST(ConfigRos2, EnabledNeedsABuildWithDds) {
  const std::string e = error_of("enabled = true");
  if (ros2::kBuiltWithDds) {
    EXPECT_EQ(e, "");
  } else {
    EXPECT_EQ(e,
              "r.toml:3: ros2.enabled = true, but this odometryd was built without the ROS 2 "
              "output (-DODO_ROS2=OFF, no Cyclone DDS): set enabled = false or use a build with "
              "-DODO_ROS2=ON");
  }
}

}  // namespace
}  // namespace odo::fw
