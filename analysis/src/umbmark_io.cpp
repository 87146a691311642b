// The UMBmark CSV reader and the SVG of the return errors before and after.
#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>

#include "odo/analysis/csv.hpp"
#include "odo/analysis/svg.hpp"
#include "odo/analysis/umbmark_tools.hpp"

namespace odo::analysis {

Result<std::vector<calib::UmbmarkRun>> read_umbmark_runs(std::istream& in,
                                                         const std::string& source) {
  CsvReader csv(in, source);
  auto cols = csv.header({"direction", "ex", "ey"}, {"etheta", "bumps"});
  if (!cols) return std::move(cols).error();
  const std::vector<int>& c = *cols;
  std::vector<calib::UmbmarkRun> out;
  std::vector<std::string> f;
  while (csv.next(f)) {
    if (f.size() != csv.columns()) {
      return csv.error("expected " + std::to_string(csv.columns()) + " fields, found " +
                       std::to_string(f.size()));
    }
    calib::UmbmarkRun r;
    const std::string& dir = f[static_cast<std::size_t>(c[0])];
    if (dir == "cw") {
      r.direction = calib::Direction::kCw;
    } else if (dir == "ccw") {
      r.direction = calib::Direction::kCcw;
    } else {
      return csv.error("field 'direction' = '" + dir + "' must be cw or ccw");
    }
    auto number = [&](int col, const char* field, const char* unit) -> Result<double> {
      auto v = csv.parse_double(f[static_cast<std::size_t>(col)], field);
      if (!v) return std::move(v).error();
      if (std::fabs(*v) > kMaxReturnError)
        return csv.range_error(return_error_range(field, *v, unit));
      return *v;
    };
    auto ex = number(c[1], "ex", "m");
    if (!ex) return std::move(ex).error();
    auto ey = number(c[2], "ey", "m");
    if (!ey) return std::move(ey).error();
    r.ex = *ex;
    r.ey = *ey;
    // An empty etheta cell: not measured on this run (only bump runs and their bias need it).
    if (c[3] >= 0 && !f[static_cast<std::size_t>(c[3])].empty()) {
      auto th = number(c[3], "etheta", "rad");
      if (!th) return std::move(th).error();
      r.etheta = *th;
    }
    if (c[4] >= 0) {
      const std::string& b = f[static_cast<std::size_t>(c[4])];
      if (b != "0" && b != "1") return csv.error("field 'bumps' = '" + b + "' must be 0 or 1");
      r.bumps = b == "1";
    }
    if (r.bumps && !r.etheta) {
      return csv.error("field 'etheta' is required on runs with bumps = 1 (extended UMBmark)");
    }
    out.push_back(r);
  }
  return out;
}

namespace {

struct Series {
  const std::vector<calib::UmbmarkRun>* runs;
  calib::CentreOfGravity cw, ccw;
  std::string label;
  bool filled;
};

}  // namespace

std::string umbmark_svg(const UmbmarkSimResult& r, const std::string& title) {
  std::vector<Series> series;
  const auto& p0 = r.passes.front().before;
  series.push_back({&p0.runs, p0.cw, p0.ccw, "before", false});
  for (std::size_t i = 0; i < r.passes.size(); ++i) {
    const auto& a = r.passes[i].after;
    series.push_back({&a.runs, a.cw, a.ccw, "after pass " + std::to_string(i + 1), true});
  }
  // Symmetric square view around the origin, in mm, big enough for every run.
  double h = 1e-3;
  for (const Series& s : series)
    for (const auto& run : *s.runs) h = std::max({h, std::fabs(run.ex), std::fabs(run.ey)});
  h *= 1.15;
  constexpr double kSize = 520.0, kMargin = 60.0;
  auto sx = [&](double v) { return kMargin + kSize * (0.5 + 0.5 * v / h); };
  auto sy = [&](double v) { return kMargin + kSize * (0.5 - 0.5 * v / h); };
  std::ostringstream s;
  s << std::setprecision(6);
  s << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << kSize + 2 * kMargin + 170
    << "\" height=\"" << kSize + 2 * kMargin << "\" font-family=\"sans-serif\" font-size=\"11\">\n"
    << "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n"
    << "<text x=\"" << kMargin << "\" y=\"20\" font-size=\"13\">" << xml_escape(title)
    << "</text>\n"
    << "<text x=\"" << kMargin << "\" y=\"38\">return errors ex, ey [mm] (truth - odometry, "
    << "start frame); blue cw, red ccw; open: before, filled: after; crosses: centres of "
    << "gravity</text>\n"
    << "<rect x=\"" << kMargin << "\" y=\"" << kMargin << "\" width=\"" << kSize << "\" height=\""
    << kSize << "\" fill=\"none\" stroke=\"black\"/>\n"
    << "<line x1=\"" << sx(-h) << "\" y1=\"" << sy(0) << "\" x2=\"" << sx(h) << "\" y2=\"" << sy(0)
    << "\" stroke=\"#bbb\"/>\n<line x1=\"" << sx(0) << "\" y1=\"" << sy(-h) << "\" x2=\"" << sx(0)
    << "\" y2=\"" << sy(h) << "\" stroke=\"#bbb\"/>\n";
  double legend_y = kMargin + 10;
  for (const Series& se : series) {
    for (const auto& run : *se.runs) {
      const char* col = run.direction == calib::Direction::kCw ? "#1f5fbf" : "#c0392b";
      s << "<circle cx=\"" << sx(run.ex) << "\" cy=\"" << sy(run.ey) << "\" r=\"3.5\" "
        << (se.filled ? std::string("fill=\"") + col + "\"" : std::string("fill=\"none\""))
        << " stroke=\"" << col << "\"><title>" << se.label << "</title></circle>\n";
    }
    for (const calib::CentreOfGravity* g : {&se.cw, &se.ccw}) {
      const char* col = g == &se.cw ? "#1f5fbf" : "#c0392b";
      const double x = sx(g->x), y = sy(g->y);
      s << "<path d=\"M" << x - 7 << "," << y << " L" << x + 7 << "," << y << " M" << x << ","
        << y - 7 << " L" << x << "," << y + 7 << "\" stroke=\"" << col
        << "\" stroke-width=\"2\"/>\n";
    }
    s << std::setprecision(4) << "<text x=\"" << 2 * kMargin + kSize << "\" y=\"" << legend_y
      << "\">" << se.label << ": r_cg cw " << se.cw.r * 1e3 << " mm, ccw " << se.ccw.r * 1e3
      << " mm</text>\n"
      << std::setprecision(6);
    legend_y += 16;
  }
  s << std::setprecision(4) << "<text x=\"" << kMargin << "\" y=\"" << kMargin + kSize + 18 << "\">"
    << -h * 1e3 << "</text>\n<text x=\"" << kMargin + kSize << "\" y=\"" << kMargin + kSize + 18
    << "\" text-anchor=\"end\">" << h * 1e3 << "</text>\n<text x=\"" << kMargin + kSize / 2
    << "\" y=\"" << kMargin + kSize + 36
    << "\" text-anchor=\"middle\">ex [mm]</text>\n<text transform=\"translate(" << kMargin - 10
    << "," << kMargin + kSize / 2 << ") rotate(-90)\" text-anchor=\"middle\">ey [mm]</text>\n";
  s << "</svg>\n";
  return s.str();
}

}  // namespace odo::analysis
