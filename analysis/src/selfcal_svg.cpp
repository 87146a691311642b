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
  int shape;  // 0 circle, 1 square, 2 triangle
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

// marker: shape s at (x, y), filled with the colour or open; `cls` names the series.
void marker(std::ostream& s, double x, double y, const Param& p, bool filled,
            const char* cls = nullptr) {
  const std::string fill = filled ? p.colour : "white";
  const std::string attrs = std::string(cls ? std::string(" class=\"") + cls + "\"" : "") +
                            " fill=\"" + fill + "\" stroke=\"" + p.colour +
                            "\" stroke-width=\"1.5\"";
  if (p.shape == 0) {
    s << "<circle cx=\"" << x << "\" cy=\"" << y << "\" r=\"4\"" << attrs << "/>\n";
  } else if (p.shape == 1) {
    s << "<rect x=\"" << x - 3.5 << "\" y=\"" << y - 3.5 << "\" width=\"7\" height=\"7\"" << attrs
      << "/>\n";
  } else {
    s << "<path d=\"M" << x << "," << y - 4.5 << " L" << x + 4.5 << "," << y + 3.5 << " L"
      << x - 4.5 << "," << y + 3.5 << " Z\"" << attrs << "/>\n";
  }
}

// Axes: x in excursions [0, xmax], y in percent [-h, h], mapped to the plot area.
struct Axes {
  double xmax, h;
  double px(double v) const { return kLeft + kW * v / xmax; }
  double py(double v) const { return kTop + kH * (0.5 - 0.5 * v / h); }
};

// axes_svg: frame, grid, ticks with labels, the zero line and both axis titles.
void axes_svg(std::ostream& s, const Axes& a) {
  // 10 intervals at most: at least 4 ticks on either axis.
  const double xs = std::max(1.0, tick_step(a.xmax, 10.0)), ys = tick_step(2.0 * a.h, 10.0);
  for (double t = 0.0; t <= a.xmax + 1e-9; t += xs) {
    s << "<line x1=\"" << a.px(t) << "\" y1=\"" << kTop << "\" x2=\"" << a.px(t) << "\" y2=\""
      << kTop + kH + 5 << "\" stroke=\"#dddddd\"/>\n<text x=\"" << a.px(t) << "\" y=\""
      << kTop + kH + 17 << "\" text-anchor=\"middle\">" << t << "</text>\n";
  }
  for (double t = std::ceil(-a.h / ys) * ys; t <= a.h + 1e-12; t += ys) {
    const double v = std::fabs(t) < 1e-9 * ys ? 0.0 : t;  // no "-0"
    s << "<line x1=\"" << kLeft - 5 << "\" y1=\"" << a.py(v) << "\" x2=\"" << kLeft + kW
      << "\" y2=\"" << a.py(v) << "\" stroke=\"" << (v == 0.0 ? "#888888" : "#dddddd")
      << "\"/>\n<text x=\"" << kLeft - 8 << "\" y=\"" << a.py(v) + 4 << "\" text-anchor=\"end\">"
      << v << "</text>\n";
  }
  s << "<rect x=\"" << kLeft << "\" y=\"" << kTop << "\" width=\"" << kW << "\" height=\"" << kH
    << "\" fill=\"none\" stroke=\"black\"/>\n<text x=\"" << kLeft + kW / 2 << "\" y=\""
    << kTop + kH + 36 << "\" text-anchor=\"middle\">excursions driven when the fit ran</text>\n"
    << "<text transform=\"translate(16," << kTop + kH / 2
    << ") rotate(-90)\" text-anchor=\"middle\">(estimate - truth) / truth [%]</text>\n";
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
