// Axes, ticks, grid and markers shared by the SVG plots of odomctl (issue 35: every plot has
// ticks and a grid on both axes and equal scales where both axes are positions).
#include "odo/analysis/svg.hpp"

#include <algorithm>
#include <iomanip>
#include <numbers>
#include <sstream>

namespace odo::analysis {
namespace {

// Ticks at the multiples of step within [lo, hi] (a hair of tolerance at the ends).
template <typename F>
void for_each_tick(double lo, double hi, double step, F f) {
  const double eps = 1e-9 * step;
  for (double k = std::ceil((lo - eps) / step); k * step <= hi + eps; k += 1.0) f(k * step);
}

// A marker outline: vertices, rotation of the first vertex [deg, 0: right, 90: down on the
// canvas], inner radius of a star (0: a plain polygon); vertices 0: a circle.
struct Shape {
  int vertices;
  double rotation;
  double inner;
};
constexpr Shape kShapes[kMarkerShapes] = {
    {0, 0, 0},       // circle
    {4, 45, 0},      // square
    {3, -90, 0},     // triangle up
    {4, 0, 0},       // diamond
    {3, 90, 0},      // triangle down
    {5, -90, 0},     // pentagon
    {6, 0, 0},       // hexagon
    {5, -90, 0.45},  // star
    {3, 0, 0},       // triangle right
    {3, 180, 0},     // triangle left
    {4, 0, 0.35},    // four-pointed star
    {6, -90, 0.5},   // six-pointed star
};

}  // namespace

void equal_scale(PlotFrame& f) {
  const double kx = (f.x1 - f.x0) / f.width, ky = (f.y1 - f.y0) / f.height;  // units per px
  const double k = std::max(kx, ky);
  const double cx = 0.5 * (f.x0 + f.x1), cy = 0.5 * (f.y0 + f.y1);
  f.x0 = cx - 0.5 * k * f.width;
  f.x1 = cx + 0.5 * k * f.width;
  f.y0 = cy - 0.5 * k * f.height;
  f.y1 = cy + 0.5 * k * f.height;
}

std::string tick_label(double v) {
  std::ostringstream t;
  t << std::setprecision(6) << (v == 0.0 ? 0.0 : v);  // -0.0 == 0.0: prints "0"
  return t.str();
}

double y_tick_room(const PlotFrame& f, double step, double font_size) {
  double w = 0.0;
  for_each_tick(f.y0, f.y1, step,
                [&](double v) { w = std::max(w, text_width(tick_label(v), font_size)); });
  return 8.0 + w + 8.0 + font_size;
}

void axes_svg(std::ostream& s, const PlotFrame& f, double x_step, double y_step,
              const std::string& x_title, const std::string& y_title, double font_size) {
  const double bottom = f.top + f.height, right = f.left + f.width;
  s << std::setprecision(6);
  for_each_tick(f.x0, f.x1, x_step, [&](double v) {
    const double x = f.px(v);
    const char* grid = std::fabs(v) < 1e-9 * x_step ? "#999999" : "#e4e4e4";
    s << "<line class=\"grid\" x1=\"" << x << "\" y1=\"" << f.top << "\" x2=\"" << x << "\" y2=\""
      << bottom << "\" stroke=\"" << grid << "\"/>\n<line x1=\"" << x << "\" y1=\"" << bottom
      << "\" x2=\"" << x << "\" y2=\"" << bottom + 5 << "\" stroke=\"black\"/>\n"
      << "<text class=\"tick-x\" x=\"" << x << "\" y=\"" << bottom + 17
      << "\" text-anchor=\"middle\">" << tick_label(v) << "</text>\n";
  });
  double label_w = 0.0;
  for_each_tick(f.y0, f.y1, y_step, [&](double v) {
    const double y = f.py(v);
    const char* grid = std::fabs(v) < 1e-9 * y_step ? "#999999" : "#e4e4e4";
    label_w = std::max(label_w, text_width(tick_label(v), font_size));
    s << "<line class=\"grid\" x1=\"" << f.left << "\" y1=\"" << y << "\" x2=\"" << right
      << "\" y2=\"" << y << "\" stroke=\"" << grid << "\"/>\n<line x1=\"" << f.left - 5
      << "\" y1=\"" << y << "\" x2=\"" << f.left << "\" y2=\"" << y << "\" stroke=\"black\"/>\n"
      << "<text class=\"tick-y\" x=\"" << f.left - 8 << "\" y=\"" << y + 4
      << "\" text-anchor=\"end\">" << tick_label(v) << "</text>\n";
  });
  s << "<rect x=\"" << f.left << "\" y=\"" << f.top << "\" width=\"" << f.width << "\" height=\""
    << f.height << "\" fill=\"none\" stroke=\"black\"/>\n<text class=\"axis-x\" x=\""
    << f.left + f.width / 2 << "\" y=\"" << bottom + 34 << "\" text-anchor=\"middle\">"
    << xml_escape(x_title) << "</text>\n<text class=\"axis-y\" transform=\"translate("
    << f.left - 8 - label_w - 8 << "," << f.top + f.height / 2
    << ") rotate(-90)\" text-anchor=\"middle\">" << xml_escape(y_title) << "</text>\n";
}

void marker_svg(std::ostream& s, int shape, double x, double y, const std::string& attrs,
                const std::string& title) {
  const Shape& sh = kShapes[static_cast<std::size_t>(shape) % kMarkerShapes];
  const std::string end =
      title.empty() ? std::string("/>\n") : "><title>" + xml_escape(title) + "</title>";
  s << std::setprecision(6);
  if (sh.vertices == 0) {
    s << "<circle cx=\"" << x << "\" cy=\"" << y << "\" r=\"3.6\" " << attrs << end
      << (title.empty() ? "" : "</circle>\n");
    return;
  }
  // Equal areas roughly: polygons with fewer vertices reach further out.
  const double r = sh.inner > 0 ? 5.2 : 4.0 + 1.5 / sh.vertices;
  const int points = sh.inner > 0 ? 2 * sh.vertices : sh.vertices;
  s << "<path d=\"";
  for (int k = 0; k < points; ++k) {
    const double a = (sh.rotation + 360.0 * k / points) * std::numbers::pi / 180.0;
    const double rk = sh.inner > 0 && k % 2 == 1 ? r * sh.inner : r;
    // Rounded to 0.01 px: the same shape has the same outline wherever it sits.
    const double dx = std::round(100.0 * rk * std::cos(a)) / 100.0;
    const double dy = std::round(100.0 * rk * std::sin(a)) / 100.0;
    s << (k == 0 ? "M" : " L") << x + dx << "," << y + dy;
  }
  s << " Z\" " << attrs << end << (title.empty() ? "" : "</path>\n");
}

}  // namespace odo::analysis
