// [ros2] validation: errors name the field, the value and the allowed range or rule.
#include <gtest/gtest.h>

#include "odo/ros2/bridge.hpp"
#include "odo/ros2/config.hpp"

namespace odo::ros2 {
namespace {

std::string message_of(const Status& s) {
  return s.ok() ? "" : s.error().message;
}

TEST(Ros2Config, DomainIdRange) {
  EXPECT_TRUE(validate_domain_id(0, "ros2.domain_id").ok());
  EXPECT_TRUE(validate_domain_id(232, "ros2.domain_id").ok());
  // 233: 7400 + 250 * 233 = 65650 > 65535, no port for it.
  EXPECT_EQ(message_of(validate_domain_id(233, "ros2.domain_id")),
            "ros2.domain_id = 233 is outside [0, 232] (DDS port mapping)");
  EXPECT_EQ(message_of(validate_domain_id(-1, "ros2.domain_id")),
            "ros2.domain_id = -1 is outside [0, 232] (DDS port mapping)");
}

TEST(Ros2Config, FrameIds) {
  for (const char* ok : {"odom", "base_link", "robot1/base_link", "_private", "a1"}) {
    EXPECT_TRUE(validate_frame_id(ok, "ros2.odom_frame").ok()) << ok;
  }
  struct Bad {
    const char* id;
    const char* says;
  };
  for (const Bad& b :
       {Bad{"", "1..255 characters"}, Bad{"/odom", "must not start with '/'"},
        Bad{"1odom", "must not start with a digit"}, Bad{"odom/", "must not end with '/'"},
        Bad{"a//b", "\"//\""}, Bad{"a__b", "\"__\""}, Bad{"base link", "A-Z a-z 0-9 _ /"},
        Bad{"odom\xc3\xa9", "A-Z a-z 0-9 _ /"}}) {
    const std::string m = message_of(validate_frame_id(b.id, "ros2.base_frame"));
    EXPECT_NE(m.find("ros2.base_frame = \"" + std::string(b.id) + "\""), std::string::npos) << m;
    EXPECT_NE(m.find(b.says), std::string::npos) << m;
  }
  EXPECT_FALSE(validate_frame_id(std::string(256, 'a'), "f").ok());
  EXPECT_TRUE(validate_frame_id(std::string(255, 'a'), "f").ok());
}

TEST(Ros2Config, NamespaceAndTopics) {
  EXPECT_TRUE(validate_namespace("", "ros2.namespace").ok());
  EXPECT_TRUE(validate_namespace("/robot1", "ros2.namespace").ok());
  EXPECT_TRUE(validate_namespace("/fleet/robot_1", "ros2.namespace").ok());
  EXPECT_NE(message_of(validate_namespace("robot1", "ros2.namespace")).find("must start with '/'"),
            std::string::npos);
  EXPECT_FALSE(validate_namespace("/", "ros2.namespace").ok());
  EXPECT_FALSE(validate_namespace("/robot1/", "ros2.namespace").ok());
  Config c;
  EXPECT_EQ(odom_topic(c), "rt/odom");
  EXPECT_EQ(set_pose_topic(c), "rt/set_pose");
  c.ns = "/robot1";
  EXPECT_EQ(odom_topic(c), "rt/robot1/odom");
  EXPECT_EQ(set_pose_topic(c), "rt/robot1/set_pose");
  EXPECT_EQ(tf_topic(), "rt/tf");  // tf2_ros uses the absolute /tf
}

TEST(Ros2Config, WholeConfig) {
  Config c;
  EXPECT_TRUE(validate(c, 1000).ok());
  c.rate_hz = 2000;
  EXPECT_EQ(message_of(validate(c, 1000)),
            "ros2.rate_hz = 2000 Hz is outside [0.1, 1000] (up to loop.rate_hz)");
  c.rate_hz = 50;
  c.base_frame = "odom";
  EXPECT_NE(message_of(validate(c, 1000)).find("ros2.base_frame = \"odom\" must differ"),
            std::string::npos);
  c.base_frame = "base_link";
  c.interfaces = {"eth0\"/><x"};
  EXPECT_NE(message_of(validate(c, 1000)).find("ros2.interfaces entry"), std::string::npos);
  c.interfaces = {"lo"};
  c.multicast = false;
  EXPECT_NE(message_of(validate(c, 1000)).find("ros2.peers must name at least one peer"),
            std::string::npos);
  c.peers = {"127.0.0.1"};
  EXPECT_TRUE(validate(c, 1000).ok());
  // spin_us: up to kSpinMaxUs (2000) and half the publish period (1 ms at 500 Hz).
  c.spin_us = 2000;
  EXPECT_TRUE(validate(c, 1000).ok());
  c.spin_us = 2001;
  EXPECT_EQ(message_of(validate(c, 1000)),
            "ros2.spin_us = 2001 us is outside [0, 2000] (at most 2000 us and half the publish "
            "period)");
  c.rate_hz = 500;
  c.spin_us = 1001;
  EXPECT_EQ(message_of(validate(c, 1000)),
            "ros2.spin_us = 1001 us is outside [0, 1000] (at most 2000 us and half the publish "
            "period)");
  c.spin_us = 1000;
  EXPECT_TRUE(validate(c, 1000).ok());
  c.spin_us = 0;
  c.rate_hz = 50;
  // And the Cyclone configuration it gives.
  EXPECT_EQ(cyclone_config_xml(c),
            "<CycloneDDS><Domain Id=\"any\"><General><Interfaces><NetworkInterface name=\"lo\"/>"
            "</Interfaces><AllowMulticast>false</AllowMulticast></General><Discovery>"
            "<ParticipantIndex>auto</ParticipantIndex><Peers><Peer address=\"127.0.0.1\"/>"
            "</Peers></Discovery></Domain></CycloneDDS>");
  EXPECT_EQ(cyclone_config_xml(Config{}), "");
}

TEST(Ros2Config, BridgeCreateRejectsBadConfigBeforeAnyDds) {
  Config c;
  c.domain_id = 300;
  auto b = Bridge::create(
      c, 100, [](OdomSample&) { return false; }, nullptr);
  ASSERT_FALSE(b.ok());
  EXPECT_EQ(b.error().message, "ros2.domain_id = 300 is outside [0, 232] (DDS port mapping)");
}

}  // namespace
}  // namespace odo::ros2
