// Small helpers shared by the SVG plots of odomctl.
#pragma once

#include <cmath>
#include <ostream>
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

// PlotFrame: one panel of a plot: its place on the canvas [px] and the value ranges it shows, in
// the units its tick labels print (mm, mrad, %, counts).
struct PlotFrame {
  double left = 0.0, top = 0.0, width = 0.0, height = 0.0;  // [px]
  double x0 = 0.0, x1 = 1.0, y0 = 0.0, y1 = 1.0;            // x0 < x1, y0 < y1
  double px(double x) const { return left + width * (x - x0) / (x1 - x0); }
  double py(double y) const { return top + height * (y1 - y) / (y1 - y0); }
};

// equal_scale: widens the narrower range of f around its centre so that one unit is as many px
// on both axes (a plot of positions shows a 30:1 ellipse as 30:1, not round).
void equal_scale(PlotFrame& f);

// tick_label: a tick value as printed: up to 6 significant digits, no "-0".
std::string tick_label(double v);

// y_tick_room: the px the y tick labels of f (step [units]) and the y axis title need left of
// the frame.
double y_tick_room(const PlotFrame& f, double step, double font_size);

// axes_svg: grid lines (class "grid"), tick marks and tick labels (class "tick-x", "tick-y")
// every x_step / y_step [units] on both axes, the frame and the axis titles (class "axis-x",
// "axis-y"), the x title 34 px below the frame, the y title left of the tick labels.
void axes_svg(std::ostream& s, const PlotFrame& f, double x_step, double y_step,
              const std::string& x_title, const std::string& y_title, double font_size);

// marker_svg: marker `shape` (kMarkerShapes of them, all different) centred at (x, y) [px], radius
// about 4 px; `attrs` (fill, stroke, class) and `title` (a tooltip; empty: none) as given.
inline constexpr int kMarkerShapes = 12;
void marker_svg(std::ostream& s, int shape, double x, double y, const std::string& attrs,
                const std::string& title = {});

}  // namespace odo::analysis
