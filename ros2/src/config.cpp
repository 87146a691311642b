#include "odo/ros2/config.hpp"

#include <cmath>
#include <sstream>

namespace odo::ros2 {
namespace {

Error reject(std::string_view field, const std::string& what) {
  return make_error(Errc::kInvalidArgument, std::string(field) + " " + what);
}

std::string quoted(std::string_view s) {
  return "\"" + std::string(s) + "\"";
}

bool name_char(char ch) {
  return (ch >= 'a' && ch <= 'z') || (ch >= 'A' && ch <= 'Z') || (ch >= '0' && ch <= '9') ||
         ch == '_' || ch == '/';
}

// The rules frame ids and namespace tokens share (ROS 2 name rules, tf2's no leading '/');
// returns "" when s follows them.
std::string name_problem(std::string_view s) {
  if (s.empty() || s.size() > kNameLengthMax) {
    return "must be 1.." + std::to_string(kNameLengthMax) + " characters";
  }
  for (char ch : s) {
    if (!name_char(ch)) return "may hold only A-Z a-z 0-9 _ /";
  }
  if (s.front() >= '0' && s.front() <= '9') return "must not start with a digit";
  if (s.front() == '/') return "must not start with '/'";
  if (s.back() == '/') return "must not end with '/'";
  if (s.find("//") != std::string_view::npos) return "must not contain \"//\"";
  if (s.find("__") != std::string_view::npos) return "must not contain \"__\"";
  return "";
}

// Interface names and peer addresses go into the DDS XML configuration: letters, digits and the
// punctuation of host names and IPv4/IPv6 addresses only.
bool address_text(std::string_view s) {
  for (char ch : s) {
    const bool ok = (ch >= 'a' && ch <= 'z') || (ch >= 'A' && ch <= 'Z') ||
                    (ch >= '0' && ch <= '9') || ch == '.' || ch == '_' || ch == '-' || ch == ':' ||
                    ch == '[' || ch == ']';
    if (!ok) return false;
  }
  return true;
}

std::string join(std::string_view prefix, std::string_view key) {
  return std::string(prefix) + "." + std::string(key);
}

}  // namespace

Status validate_domain_id(std::int64_t domain_id, std::string_view field) {
  if (domain_id < 0 || domain_id > kDomainIdMax) {
    return reject(field, "= " + std::to_string(domain_id) + " is outside [0, " +
                             std::to_string(kDomainIdMax) + "] (DDS port mapping)");
  }
  return Ok{};
}

Status validate_frame_id(std::string_view id, std::string_view field) {
  const std::string p = name_problem(id);
  if (!p.empty()) return reject(field, "= " + quoted(id) + " " + p + " (a tf2 frame id)");
  return Ok{};
}

Status validate_namespace(std::string_view ns, std::string_view field) {
  if (ns.empty()) return Ok{};
  const std::string p = ns.front() == '/' ? name_problem(ns.substr(1)) : "must start with '/'";
  if (!p.empty()) return reject(field, "= " + quoted(ns) + " " + p + " (\"\" or \"/name\")");
  return Ok{};
}

Status validate(const Config& c, double loop_rate_hz, std::string_view prefix) {
  if (auto s = validate_domain_id(c.domain_id, join(prefix, "domain_id")); !s) return s;
  if (auto s = validate_namespace(c.ns, join(prefix, "namespace")); !s) return s;
  if (auto s = validate_frame_id(c.odom_frame, join(prefix, "odom_frame")); !s) return s;
  if (auto s = validate_frame_id(c.base_frame, join(prefix, "base_frame")); !s) return s;
  if (c.odom_frame == c.base_frame) {
    return reject(join(prefix, "base_frame"),
                  "= " + quoted(c.base_frame) + " must differ from odom_frame");
  }
  if (!(c.rate_hz >= kRateMinHz && c.rate_hz <= loop_rate_hz)) {
    std::ostringstream m;
    m << "= " << c.rate_hz << " Hz is outside [" << kRateMinHz << ", " << loop_rate_hz
      << "] (up to loop.rate_hz)";
    return reject(join(prefix, "rate_hz"), m.str());
  }
  for (const auto& i : c.interfaces) {
    if (i.empty() || i.size() > 15 || !address_text(i)) {
      return reject(join(prefix, "interfaces"), "entry " + quoted(i) +
                                                    " must be 1..15 characters of A-Z a-z 0-9 . _ "
                                                    "- : (a network interface)");
    }
  }
  for (const auto& p : c.peers) {
    if (p.empty() || p.size() > kNameLengthMax || !address_text(p)) {
      return reject(join(prefix, "peers"), "entry " + quoted(p) +
                                               " must be a host name or address (A-Z a-z 0-9 . _ "
                                               "- : [ ])");
    }
  }
  if (!c.multicast && c.peers.empty()) {
    return reject(join(prefix, "peers"),
                  "must name at least one peer when multicast = false (nothing to discover)");
  }
  return Ok{};
}

std::string odom_topic(const Config& c) {
  return "rt" + c.ns + "/odom";
}
std::string set_pose_topic(const Config& c) {
  return "rt" + c.ns + "/set_pose";
}
std::string tf_topic() {
  return "rt/tf";
}

}  // namespace odo::ros2
