// SVG of the self-calibration's convergence (`odomctl selfcal simulate --plot`, issue 18).
#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>

#include "odo/analysis/selfcal_tools.hpp"
#include "odo/analysis/svg.hpp"

namespace odo::analysis {
namespace {

constexpr double kW = 520.0, kH = 300.0;  // plot area [px]
constexpr double kLeft = 70.0, kTop = 62.0, kFont = 11.0;
constexpr double kBarCap = 2.0;  // a bar reaches at most this many times the largest error

// One parameter's series: its name, colour, marker shape and x offset (bars side by side).
struct Param {
  const char* name;
  const char* label;
  const char* colour;
  int shape;  // marker_svg: 0 circle, 1 square, 2 triangle
  double dx;  // [px]
};
constexpr Param kParams[3] = {{"c_l", "c_L", "#1f5fbf", 0, -6.0},
                              {"c_r", "c_R", "#c0392b", 1, 0.0},
                              {"b", "b", "#2e8b3e", 2, 6.0}};
constexpr Param kNeutral = {"", "", "#555555", 0, 0.0};  // the legend's applied / not applied

// rel_error: (estimate - truth) / truth [%] of parameter i, and its 1-sigma [%].
std::array<double, 2> rel_error(const SelfCalFitPoint& p, const calib::Factors& truth, int i) {
  const double est[3] = {p.estimate.c_l, p.estimate.c_r, p.estimate.wheelbase};
  const double tr[3] = {truth.c_l, truth.c_r, truth.wheelbase};
  return {100.0 * (est[i] - tr[i]) / tr[i], 100.0 * p.sigma[static_cast<std::size_t>(i)] / tr[i]};
}

// marker: the parameter's shape at (x, y), filled with its colour or open; `cls` names the series.
void marker(std::ostream& s, double x, double y, const Param& p, bool filled,
            const char* cls = nullptr) {
  const std::string fill = filled ? p.colour : "white";
  marker_svg(s, p.shape, x, y,
             std::string(cls ? std::string("class=\"") + cls + "\" " : "") + "fill=\"" + fill +
                 "\" stroke=\"" + p.colour + "\" stroke-width=\"1.5\"");
}

// Axes: x in excursions [0, xmax], y in percent [-h, h], mapped to the plot area.
struct Axes {
  double xmax, h;
  PlotFrame frame() const { return {kLeft, kTop, kW, kH, 0.0, xmax, -h, h}; }
  double px(double v) const { return frame().px(v); }
  double py(double v) const { return frame().py(v); }
};

// axes_svg: frame, grid, ticks with labels, the zero line and both axis titles. 10 intervals at
// most: at least 4 ticks on either axis; whole excursions on x.
void axes_svg(std::ostream& s, const Axes& a) {
  analysis::axes_svg(s, a.frame(), std::max(1.0, tick_step(a.xmax, 10.0)),
                     tick_step(2.0 * a.h, 10.0), "excursions driven when the fit ran",
                     "(estimate - truth) / truth [%]", kFont);
}

// axes_for: x up to the last fit's excursion count; y symmetric around 0, holding every
// error and its bar, bars limited to kBarCap times the largest error (an early fit's sigma
// can be orders of magnitude larger and would flatten the rest; it is drawn to the edge).
Axes axes_for(const std::vector<SelfCalFitPoint>& fits, const calib::Factors& truth) {
  double xmax = 1.0, e = 1e-3, h = 0.0;
  for (const SelfCalFitPoint& p : fits) {
    xmax = std::max(xmax, static_cast<double>(p.excursions));
    for (int i = 0; i < 3; ++i) e = std::max(e, std::fabs(rel_error(p, truth, i)[0]));
  }
  for (const SelfCalFitPoint& p : fits) {
    for (int i = 0; i < 3; ++i) {
      const auto r = rel_error(p, truth, i);
      h = std::max(h, std::min(std::fabs(r[0]) + r[1], kBarCap * e));
    }
  }
  return {xmax * 1.05 + 0.5, std::max(h, e) * 1.1};
}

// points_svg: every fit's three markers with their 1-sigma bars (clipped to the plot).
void points_svg(std::ostream& s, const Axes& a, const std::vector<SelfCalFitPoint>& fits,
                const calib::Factors& truth) {
  for (int i = 0; i < 3; ++i) {
    const Param& q = kParams[i];
    const std::string cls = std::string("fit ") + q.name;
    for (const SelfCalFitPoint& p : fits) {
      const auto r = rel_error(p, truth, i);
      const double x = a.px(p.excursions) + q.dx;
      const double lo = std::max(r[0] - r[1], -a.h), hi = std::min(r[0] + r[1], a.h);
      if (lo < hi) {
        s << "<line x1=\"" << x << "\" y1=\"" << a.py(lo) << "\" x2=\"" << x << "\" y2=\""
          << a.py(hi) << "\" stroke=\"" << q.colour << "\"/>\n";
      }
      marker(s, x, a.py(std::clamp(r[0], -a.h, a.h)), q, p.applied, cls.c_str());
    }
  }
}

}  // namespace

std::string selfcal_svg(const std::vector<SelfCalFitPoint>& fits, const calib::Factors& truth,
                        const std::vector<std::string>& notes, const std::string& title) {
  const Axes a = axes_for(fits, truth);
  const std::string sub1 =
      "relative error of each fit's estimate against the truth, bars: 1 sigma of the fit";
  const std::string sub2 = "filled: applied (accepted and posted to the loop), open: not applied";
  const std::vector<std::string> legend = {"c_L", "c_R", "b (wheelbase)", "applied", "not applied"};
  const double legend_x = kLeft + kW + 30, notes_y = kTop + kH + 60;
  double width = legend_x;
  for (const std::string& l : legend) width = std::max(width, legend_x + 16 + text_width(l, kFont));
  for (const std::string& l : notes) width = std::max(width, kLeft + text_width(l, kFont));
  width = std::max({width, kLeft + text_width(title, 13), kLeft + text_width(sub1, kFont),
                    kLeft + text_width(sub2, kFont)}) +
          10;
  const double height = notes_y + 16.0 * static_cast<double>(notes.size()) + 10;
  std::ostringstream s;
  s << std::setprecision(6) << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << width
    << "\" height=\"" << height << "\" font-family=\"sans-serif\" font-size=\"" << kFont
    << "\">\n<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n<text x=\"" << kLeft
    << "\" y=\"18\" font-size=\"13\">" << xml_escape(title) << "</text>\n<text x=\"" << kLeft
    << "\" y=\"34\">" << xml_escape(sub1) << "</text>\n<text x=\"" << kLeft << "\" y=\"48\">"
    << xml_escape(sub2) << "</text>\n";
  axes_svg(s, a);
  points_svg(s, a, fits, truth);
  for (std::size_t i = 0; i < legend.size(); ++i) {
    const double y = kTop + 10 + 18 * static_cast<double>(i);
    marker(s, legend_x + 4, y - 4, i < 3 ? kParams[i] : kNeutral, i != 4);
    s << "<text x=\"" << legend_x + 16 << "\" y=\"" << y << "\">" << xml_escape(legend[i])
      << "</text>\n";
  }
  for (std::size_t i = 0; i < notes.size(); ++i) {
    s << "<text x=\"" << kLeft << "\" y=\"" << notes_y + 16.0 * static_cast<double>(i) << "\">"
      << xml_escape(notes[i]) << "</text>\n";
  }
  s << "</svg>\n";
  return s.str();
}

}  // namespace odo::analysis
