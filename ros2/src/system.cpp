// The parts of the bridge that need no DDS: the clock offset of the time stamps and the Cyclone
// DDS configuration text (built with -DODO_ROS2=OFF too).
#include "clock.hpp"
#include "odo/ros2/bridge.hpp"

namespace odo::ros2 {

TimeNs realtime_minus_monotonic() {
  const TimeNs m0 = now_ns(CLOCK_MONOTONIC);
  const TimeNs r = now_ns(CLOCK_REALTIME);
  const TimeNs m1 = now_ns(CLOCK_MONOTONIC);
  return r - (m0 + (m1 - m0) / 2);
}

std::string cyclone_config_xml(const Config& c) {
  if (c.interfaces.empty() && c.peers.empty() && c.multicast) return "";
  // Validated text only (config.cpp: address_text), so nothing here needs XML escaping.
  std::string x = "<CycloneDDS><Domain Id=\"any\"><General>";
  if (!c.interfaces.empty()) {
    x += "<Interfaces>";
    for (const auto& i : c.interfaces) {
      x += "<NetworkInterface name=\"" + i + "\"" + (c.multicast ? " multicast=\"true\"" : "") +
           "/>";
    }
    x += "</Interfaces>";
  }
  x += std::string("<AllowMulticast>") + (c.multicast ? "true" : "false") + "</AllowMulticast>";
  x += "</General>";
  if (!c.peers.empty()) {
    x += "<Discovery><ParticipantIndex>auto</ParticipantIndex><Peers>";
    for (const auto& p : c.peers) x += "<Peer address=\"" + p + "\"/>";
    x += "</Peers></Discovery>";
  }
  x += "</Domain></CycloneDDS>";
  return x;
}

}  // namespace odo::ros2
