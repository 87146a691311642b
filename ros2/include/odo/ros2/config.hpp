// Configuration of the ROS 2 output ([ros2] in odometryd.toml) and its validation. Errors name
// the field, the value and the allowed range; the config reader prefixes file and line.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "odo/hal/result.hpp"

namespace odo::ros2 {

// DDS port mapping (RTPS 9.6.1.1, PB 7400 + DG 250 * domain + offsets up to 11 + 2 * participant)
// must stay below 65536: domains 0..232, the range ROS 2 documents for ROS_DOMAIN_ID.
inline constexpr std::uint32_t kDomainIdMax = 232;
inline constexpr std::size_t kNameLengthMax = 255;  // frame ids and the namespace [characters]
inline constexpr double kRateMinHz = 0.1;
// The publish thread's SCHED_FIFO priority stays below the kernel's 99 (migration, watchdog).
inline constexpr int kPriorityMax = 98;
// The publish thread's early wake-up (spin_us): at most 2 ms, and at most half the publish period.
inline constexpr int kSpinMaxUs = 2000;
// kBuiltWithDds: this build has the DDS bridge (-DODO_ROS2=ON); without it the configuration is
// still read and checked, and enabled = true is an error.
inline constexpr bool kBuiltWithDds = ODO_ROS2_DDS != 0;

struct Config {
  bool enabled = false;
  std::uint32_t domain_id = 0;           // ROS_DOMAIN_ID of the ROS 2 computer
  std::string ns;                        // topic namespace: "" or "/robot1" -> rt/robot1/odom
  std::string odom_frame = "odom";       // header.frame_id of /odom and of the transform
  std::string base_frame = "base_link";  // child_frame_id
  double rate_hz = 50.0;                 // publish rate, kRateMinHz .. the loop rate [Hz]
  bool publish_tf = true;                // also publish odom -> base_link on rt/tf
  std::vector<std::string> interfaces;   // network interfaces DDS may use ({} = DDS's choice)
  std::vector<std::string> peers;        // unicast discovery peers ({} = multicast only)
  bool multicast = true;                 // SPDP multicast discovery (false: peers only)
  int priority = 0;  // SCHED_FIFO priority of the publish thread, 1..kPriorityMax; 0: normal
  // Early wake-up of the publish thread [us]: it wakes this long before a due tick and polls the
  // loop's buffer (a bounded busy wait) until that tick's sample is there, so that its own
  // wake-up is not in the sample-to-receipt latency; 0: it sleeps until just after the tick.
  int spin_us = 0;
};

// validate_domain_id: domain_id in [0, kDomainIdMax].
Status validate_domain_id(std::int64_t domain_id, std::string_view field);

// validate_frame_id: a tf2 frame id: 1..255 characters of [A-Za-z0-9_/], not starting with a
// digit or '/' (tf2 rejects a leading slash), no "//", no trailing '/', no "__".
Status validate_frame_id(std::string_view id, std::string_view field);

// validate_namespace: "" or a ROS 2 absolute namespace "/a/b" whose tokens follow the frame id
// rules.
Status validate_namespace(std::string_view ns, std::string_view field);

// ConfigProblem: the first invalid key of a Config ("domain_id", "rate_hz", ...) and what is
// wrong with it ("= 300 is outside [0, 232] ..."), for a reader that prefixes file, line, table.
struct ConfigProblem {
  std::string key;
  std::string what;
};

// check: the first problem of c, in field order (loop_rate_hz bounds rate_hz); nullopt if none.
std::optional<ConfigProblem> check(const Config& c, double loop_rate_hz);

// validate: every field of c; loop_rate_hz bounds rate_hz. Field names are "<prefix>.<key>".
Status validate(const Config& c, double loop_rate_hz, std::string_view prefix = "ros2");

// Topic names on the wire (ROS 2 prefixes "rt" to topics): rt<ns>/odom, rt<ns>/set_pose and
// rt/tf (tf2_ros listens on the absolute /tf whatever the namespace).
std::string odom_topic(const Config& c);
std::string set_pose_topic(const Config& c);
std::string tf_topic();

}  // namespace odo::ros2
