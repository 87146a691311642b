// Small helpers shared by the SVG plots of odomctl.
#pragma once

#include <string>

namespace odo::analysis {

// xml_escape: text content for an SVG (titles name "Chong & Kleeman").
inline std::string xml_escape(const std::string& t) {
  std::string out;
  for (char ch : t) {
    switch (ch) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      default:
        out += ch;
    }
  }
  return out;
}

}  // namespace odo::analysis
