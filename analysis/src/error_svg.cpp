// SVG of 95% error ellipses, predicted against sample (Chong & Kleeman Fig. 4).
#include <algorithm>
#include <cmath>
#include <iomanip>
#include <numbers>
#include <sstream>

#include "odo/analysis/error_model_tools.hpp"
#include "odo/analysis/svg.hpp"

namespace odo::analysis {
namespace {

// Chi-square quantile for 95% with 2 degrees of freedom: -2 ln(0.05).
const double kChi2_95 = -2.0 * std::log(0.05);
constexpr double kPanel = 300.0;  // panel size [px]
constexpr double kTop = 75.0;     // room for the title lines above the panels [px]
constexpr std::size_t kMaxDots = 3000;

// Human units at the edge: millimetres and milliradians, labelled.
constexpr double kScale[3] = {1e3, 1e3, 1e3};
constexpr const char* kLabel[3] = {"ex [mm]", "ey [mm]", "etheta [mrad]"};

// ellipse_points: the 95% ellipse of the 2 x 2 block (i, j) of c, around (mx, my), as points.
std::vector<std::array<double, 2>> ellipse_points(const Cov3& c, int i, int j, double mx,
                                                  double my) {
  const double a = c[4 * i], b = c[3 * i + j], d = c[4 * j];
  const double mean = 0.5 * (a + d), diff = 0.5 * (a - d);
  const double root = std::sqrt(diff * diff + b * b);
  const double l1 = std::max(mean + root, 0.0), l2 = std::max(mean - root, 0.0);
  const double phi = 0.5 * std::atan2(2.0 * b, a - d);
  const double r1 = std::sqrt(kChi2_95 * l1), r2 = std::sqrt(kChi2_95 * l2);
  std::vector<std::array<double, 2>> pts;
  for (int k = 0; k <= 120; ++k) {
    const double t = 2.0 * std::numbers::pi * k / 120.0;
    const double u = r1 * std::cos(t), v = r2 * std::sin(t);
    pts.push_back(
        {mx + u * std::cos(phi) - v * std::sin(phi), my + u * std::sin(phi) + v * std::cos(phi)});
  }
  return pts;
}

// Panel: which pair (i, j) panel number p shows, and its frame in display units (kScale).
struct Panel {
  int p = 0, i = 0, j = 0;
  PlotFrame f;
  double sx(double v) const { return f.px(v * kScale[i]); }
  double sy(double v) const { return f.py(v * kScale[j]); }
};

// frame_ranges: the larger ellipse plus a margin around the mean (outlying dots may fall off
// the panel), in display units; equal scales when both axes are positions (ex, ey).
void frame_ranges(Panel& q, const std::vector<std::array<double, 2>>& pred,
                  const std::vector<std::array<double, 2>>& samp, double mi, double mj) {
  double hx = 0.0, hy = 0.0;
  for (const auto* e : {&pred, &samp}) {
    for (const auto& pt : *e) {
      hx = std::max(hx, std::fabs(pt[0] - mi));
      hy = std::max(hy, std::fabs(pt[1] - mj));
    }
  }
  hx = std::max(hx * 1.4, 1e-12) * kScale[q.i];
  hy = std::max(hy * 1.4, 1e-12) * kScale[q.j];
  q.f.x0 = mi * kScale[q.i] - hx;
  q.f.x1 = mi * kScale[q.i] + hx;
  q.f.y0 = mj * kScale[q.j] - hy;
  q.f.y1 = mj * kScale[q.j] + hy;
  if (q.i < 2 && q.j < 2) equal_scale(q.f);
}

// write_plot: the panel's axes, the run dots and both ellipses (clipped to the panel).
void write_plot(std::ostream& s, const Panel& q, const std::vector<PoseError>& errors,
                const std::vector<std::array<double, 2>>& pred,
                const std::vector<std::array<double, 2>>& samp) {
  s << "<g class=\"panel\">\n";
  axes_svg(s, q.f, tick_step(q.f.x1 - q.f.x0), tick_step(q.f.y1 - q.f.y0), kLabel[q.i], kLabel[q.j],
           11.0);
  s << "<clipPath id=\"c" << q.p << "\"><rect x=\"" << q.f.left << "\" y=\"" << q.f.top
    << "\" width=\"" << kPanel << "\" height=\"" << kPanel
    << "\"/></clipPath>\n<g clip-path=\"url(#c" << q.p << ")\">\n";
  const std::size_t n = std::min(errors.size(), kMaxDots);
  for (std::size_t k = 0; k < n; ++k) {
    s << "<circle cx=\"" << q.sx(errors[k][q.i]) << "\" cy=\"" << q.sy(errors[k][q.j])
      << "\" r=\"1.2\" fill=\"#7a9cc6\"/>\n";
  }
  auto poly = [&](const std::vector<std::array<double, 2>>& pts, const char* style) {
    s << "<polyline fill=\"none\" " << style << " points=\"";
    for (const auto& pt : pts) s << q.sx(pt[0]) << "," << q.sy(pt[1]) << " ";
    s << "\"/>\n";
  };
  poly(samp, "stroke=\"black\" stroke-width=\"1.5\"");
  poly(pred, "stroke=\"#c0392b\" stroke-width=\"1.5\" stroke-dasharray=\"6,4\"");
  s << "</g>\n</g>\n";
}

}  // namespace

std::string error_ellipse_svg(const std::vector<PoseError>& errors, const Cov3& predicted,
                              const Cov3& sample, const PoseError& mean, const std::string& title) {
  const int pairs[3][2] = {{0, 1}, {0, 2}, {1, 2}};
  const std::string sub =
      "dots: runs; solid: 95% ellipse of the sample; dashed: 95% ellipse predicted by the closed "
      "form (both around the sample mean); ex-ey on equal scales";
  std::ostringstream body;
  body << std::setprecision(6);
  double left = 20.0;  // the next panel's room for its y tick labels starts here
  for (int p = 0; p < 3; ++p) {
    Panel q;
    q.p = p;
    q.i = pairs[p][0];
    q.j = pairs[p][1];
    const auto pred = ellipse_points(predicted, q.i, q.j, mean[q.i], mean[q.j]);
    const auto samp = ellipse_points(sample, q.i, q.j, mean[q.i], mean[q.j]);
    q.f = PlotFrame{0.0, kTop, kPanel, kPanel};
    frame_ranges(q, pred, samp, mean[q.i], mean[q.j]);
    q.f.left = left + y_tick_room(q.f, tick_step(q.f.y1 - q.f.y0), 11.0);
    write_plot(body, q, errors, pred, samp);
    left = q.f.left + kPanel + 10.0;
  }
  // Wide enough for the three panels and for the title lines, whatever their length.
  const double width =
      std::max({left + 10.0, 20.0 + text_width(title, 13) + 10, 20.0 + text_width(sub, 11.0) + 10});
  const double height = kTop + kPanel + 50.0;
  std::ostringstream s;
  s << std::setprecision(6) << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << width
    << "\" height=\"" << height << "\" font-family=\"sans-serif\" font-size=\"11\">\n"
    << "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n"
    << "<text x=\"20\" y=\"18\" font-size=\"13\">" << xml_escape(title) << "</text>\n"
    << "<text x=\"20\" y=\"34\">" << xml_escape(sub) << "</text>\n"
    << body.str() << "</svg>\n";
  return s.str();
}

}  // namespace odo::analysis
