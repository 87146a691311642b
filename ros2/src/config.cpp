#include "odo/ros2/config.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <utility>

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

std::string domain_id_problem(std::int64_t domain_id) {
  if (domain_id >= 0 && domain_id <= kDomainIdMax) return "";
  return "= " + std::to_string(domain_id) + " is outside [0, " + std::to_string(kDomainIdMax) +
         "] (DDS port mapping)";
}

std::string frame_id_problem(std::string_view id) {
  const std::string p = name_problem(id);
  return p.empty() ? "" : "= " + quoted(id) + " " + p + " (a tf2 frame id)";
}

std::string namespace_problem(std::string_view ns) {
  if (ns.empty()) return "";
  const std::string p = ns.front() == '/' ? name_problem(ns.substr(1)) : "must start with '/'";
  return p.empty() ? "" : "= " + quoted(ns) + " " + p + " (\"\" or \"/name\")";
}

std::string rate_problem(double rate_hz, double loop_rate_hz) {
  if (rate_hz >= kRateMinHz && rate_hz <= loop_rate_hz) return "";
  std::ostringstream m;
  m << "= " << rate_hz << " Hz is outside [" << kRateMinHz << ", " << loop_rate_hz
    << "] (up to loop.rate_hz)";
  return m.str();
}

std::string priority_problem(int priority) {
  if (priority >= 0 && priority <= kPriorityMax) return "";
  return "= " + std::to_string(priority) + " is outside [0, " + std::to_string(kPriorityMax) +
         "] (0: normal scheduling)";
}

std::string spin_problem(int spin_us, double rate_hz) {
  // Half the publish period: the thread must sleep most of it (and spin_us is at most 2 ms).
  const int max_us = static_cast<int>(std::min<double>(kSpinMaxUs, std::floor(0.5e6 / rate_hz)));
  if (spin_us >= 0 && spin_us <= max_us) return "";
  return "= " + std::to_string(spin_us) + " us is outside [0, " + std::to_string(max_us) +
         "] (at most " + std::to_string(kSpinMaxUs) + " us and half the publish period)";
}

std::string interfaces_problem(const std::vector<std::string>& interfaces) {
  for (const auto& i : interfaces) {
    if (i.empty() || i.size() > 15 || !address_text(i)) {
      return "entry " + quoted(i) +
             " must be 1..15 characters of A-Z a-z 0-9 . _ - : (a network interface)";
    }
  }
  return "";
}

std::string peers_problem(const Config& c) {
  for (const auto& p : c.peers) {
    if (p.empty() || p.size() > kNameLengthMax || !address_text(p)) {
      return "entry " + quoted(p) + " must be a host name or address (A-Z a-z 0-9 . _ - : [ ])";
    }
  }
  if (!c.multicast && c.peers.empty()) {
    return "must name at least one peer when multicast = false (nothing to discover)";
  }
  return "";
}

Status as_status(std::string_view field, const std::string& problem) {
  if (problem.empty()) return Ok{};
  return reject(field, problem);
}

}  // namespace

Status validate_domain_id(std::int64_t domain_id, std::string_view field) {
  return as_status(field, domain_id_problem(domain_id));
}

Status validate_frame_id(std::string_view id, std::string_view field) {
  return as_status(field, frame_id_problem(id));
}

Status validate_namespace(std::string_view ns, std::string_view field) {
  return as_status(field, namespace_problem(ns));
}

std::optional<ConfigProblem> check(const Config& c, double loop_rate_hz) {
  const std::pair<std::string_view, std::string> checks[] = {
      {"domain_id", domain_id_problem(c.domain_id)},
      {"namespace", namespace_problem(c.ns)},
      {"odom_frame", frame_id_problem(c.odom_frame)},
      {"base_frame", frame_id_problem(c.base_frame)},
      {"base_frame", c.odom_frame == c.base_frame
                         ? "= " + quoted(c.base_frame) + " must differ from odom_frame"
                         : ""},
      {"rate_hz", rate_problem(c.rate_hz, loop_rate_hz)},
      {"interfaces", interfaces_problem(c.interfaces)},
      {"peers", peers_problem(c)},
      {"priority", priority_problem(c.priority)},
      {"spin_us", spin_problem(c.spin_us, c.rate_hz)}};
  for (const auto& [key, what] : checks) {
    if (!what.empty()) return ConfigProblem{std::string(key), what};
  }
  return std::nullopt;
}

Status validate(const Config& c, double loop_rate_hz, std::string_view prefix) {
  if (auto p = check(c, loop_rate_hz)) return reject(join(prefix, p->key), p->what);
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
