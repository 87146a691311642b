// Small helpers shared by the SVG plots of odomctl.
#pragma once

#include <cmath>
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

// text_width: a generous estimate [px] of one line of sans-serif text (0.62 em a character;
// DejaVu Sans averages about 0.55 em), so that a canvas can be sized to hold it.
inline double text_width(const std::string& t, double font_size) {
  return 0.62 * font_size * static_cast<double>(t.size());
}

// tick_step: the smallest 1, 2 or 5 times a power of ten not below span / intervals, i.e.
// intervals / 2.5 to `intervals` intervals over a range `span` wide.
inline double tick_step(double span, double intervals = 8.0) {
  const double raw = span / intervals;
  const double p = std::pow(10.0, std::floor(std::log10(raw)));
  for (double m : {1.0, 2.0, 5.0, 10.0})
    if (m * p >= raw) return m * p;
  return 10.0 * p;
}

}  // namespace odo::analysis
