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
constexpr double kMargin = 50.0;  // room for labels [px]
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

// Panel: where the (i, j) panel number p sits, its half-ranges around the mean, and the
// mapping of error values to SVG coordinates.
struct Panel {
  int p = 0, i = 0, j = 0;
  double ox = 0, oy = 0, hx = 0, hy = 0, mi = 0, mj = 0;
  double sx(double v) const { return ox + kPanel * (0.5 + 0.5 * (v - mi) / hx); }
  double sy(double v) const { return oy + kPanel * (0.5 - 0.5 * (v - mj) / hy); }
};

// half_range: the larger ellipse plus a margin, so outlying dots may fall off the panel.
void half_range(Panel& q, const std::vector<std::array<double, 2>>& pred,
                const std::vector<std::array<double, 2>>& samp) {
  double hx = 0.0, hy = 0.0;
  for (const auto* e : {&pred, &samp}) {
    for (const auto& pt : *e) {
      hx = std::max(hx, std::fabs(pt[0] - q.mi));
      hy = std::max(hy, std::fabs(pt[1] - q.mj));
    }
  }
  q.hx = std::max(hx * 1.4, 1e-12);
  q.hy = std::max(hy * 1.4, 1e-12);
}

// write_plot: the panel's frame, the run dots and both ellipses (clipped to the panel).
void write_plot(std::ostream& s, const Panel& q, const std::vector<PoseError>& errors,
                const std::vector<std::array<double, 2>>& pred,
                const std::vector<std::array<double, 2>>& samp) {
  s << "<g>\n<rect x=\"" << q.ox << "\" y=\"" << q.oy << "\" width=\"" << kPanel << "\" height=\""
    << kPanel << "\" fill=\"none\" stroke=\"black\"/>\n";
  s << "<clipPath id=\"c" << q.p << "\"><rect x=\"" << q.ox << "\" y=\"" << q.oy << "\" width=\""
    << kPanel << "\" height=\"" << kPanel << "\"/></clipPath>\n<g clip-path=\"url(#c" << q.p
    << ")\">\n";
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
  s << "</g>\n";
}

// write_axes: axis labels and the extreme values of each axis, in mm / mrad.
void write_axes(std::ostream& s, const Panel& q) {
  const double ox = q.ox, oy = q.oy;
  s << std::setprecision(3);
  s << "<text x=\"" << ox + kPanel / 2 << "\" y=\"" << oy + kPanel + 30
    << "\" text-anchor=\"middle\">" << kLabel[q.i] << "</text>\n"
    << "<text x=\"" << ox << "\" y=\"" << oy + kPanel + 14 << "\">" << (q.mi - q.hx) * kScale[q.i]
    << "</text>\n"
    << "<text x=\"" << ox + kPanel << "\" y=\"" << oy + kPanel + 14 << "\" text-anchor=\"end\">"
    << (q.mi + q.hx) * kScale[q.i] << "</text>\n"
    << "<text transform=\"translate(" << ox - 8 << "," << oy + kPanel / 2
    << ") rotate(-90)\" text-anchor=\"middle\">" << kLabel[q.j] << "</text>\n"
    << "<text x=\"" << ox + 3 << "\" y=\"" << oy + 12 << "\">" << (q.mj + q.hy) * kScale[q.j]
    << "</text>\n"
    << "<text x=\"" << ox + 3 << "\" y=\"" << oy + kPanel - 4 << "\">"
    << (q.mj - q.hy) * kScale[q.j] << "</text>\n";
  s << std::setprecision(6);
}

}  // namespace

std::string error_ellipse_svg(const std::vector<PoseError>& errors, const Cov3& predicted,
                              const Cov3& sample, const PoseError& mean, const std::string& title) {
  const int pairs[3][2] = {{0, 1}, {0, 2}, {1, 2}};
  // Wide enough for the three panels and for the title, whatever its length.
  const double width =
      std::max(3 * (kPanel + kMargin) + kMargin, kMargin + text_width(title, 13) + 10);
  const double height = kPanel + 2.5 * kMargin;
  std::ostringstream s;
  s << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << width << "\" height=\"" << height
    << "\" font-family=\"sans-serif\" font-size=\"11\">\n"
    << "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n"
    << "<text x=\"" << kMargin << "\" y=\"18\" font-size=\"13\">" << xml_escape(title)
    << "</text>\n"
    << "<text x=\"" << kMargin << "\" y=\"34\">dots: runs; solid: 95% ellipse of the sample; "
    << "dashed: 95% ellipse predicted by the closed form (both around the sample mean)</text>\n";
  for (int p = 0; p < 3; ++p) {
    Panel q;
    q.p = p;
    q.i = pairs[p][0];
    q.j = pairs[p][1];
    q.mi = mean[q.i];
    q.mj = mean[q.j];
    q.ox = kMargin + p * (kPanel + kMargin);
    q.oy = 1.5 * kMargin;
    const auto pred = ellipse_points(predicted, q.i, q.j, q.mi, q.mj);
    const auto samp = ellipse_points(sample, q.i, q.j, q.mi, q.mj);
    half_range(q, pred, samp);
    write_plot(s, q, errors, pred, samp);
    write_axes(s, q);
    s << "</g>\n";
  }
  s << "</svg>\n";
  return s.str();
}

}  // namespace odo::analysis
