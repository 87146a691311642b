#include "odo/protocol/signals.hpp"

#include <cstdio>
#include <string>

namespace odo::protocol {

std::string dbc_decimal(double v) {
  // Plain decimals (0.00001, not 1e-05): some DBC readers drop signals written otherwise.
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.9f", v);
  std::string s = buf;
  while (!s.empty() && s.back() == '0') s.pop_back();
  if (!s.empty() && s.back() == '.') s.pop_back();
  return s == "-0" ? "0" : s;
}

std::string dbc_message_line(const MessageSpec& m) {
  const std::uint32_t id = frame_id(kDefaultBaseId, kDefaultNodeId, m.msg);
  return "BO_ " + std::to_string(id) + " " + m.name + ": 8 " +
         (m.to_node ? "RECEIVER" : "ODOMETRY");
}

std::string dbc_signal_line(const MessageSpec& m, const Signal& s) {
  return std::string(" SG_ ") + s.name + " : " + std::to_string(s.start_bit) + "|" +
         std::to_string(s.width) + "@1" + (s.is_signed ? "-" : "+") + " (" + dbc_decimal(s.scale) +
         ",0) [" + dbc_decimal(static_cast<double>(s.raw_min) * s.scale) + "|" +
         dbc_decimal(static_cast<double>(s.raw_max) * s.scale) + "] \"" + s.unit + "\" " +
         (m.to_node ? "ODOMETRY" : "RECEIVER");
}

}  // namespace odo::protocol
