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

std::string format_umbmark_runs(const std::vector<calib::UmbmarkRun>& runs) {
  std::ostringstream s;
  s << "direction,ex,ey,etheta,bumps\n" << std::fixed;
  for (const calib::UmbmarkRun& r : runs) {
    s << (r.direction == calib::Direction::kCw ? "cw" : "ccw") << "," << std::setprecision(4)
      << r.ex << "," << r.ey << ",";
    if (r.etheta) s << std::setprecision(5) << *r.etheta;
    s << "," << (r.bumps ? 1 : 0) << "\n";
  }
  return s.str();
}

namespace {

struct Series {
  const std::vector<calib::UmbmarkRun>* runs;
  calib::CentreOfGravity cw, ccw;
  std::string label;
  int shape;  // 0: open circle (before), 1..: filled circle, square, triangle, diamond
};

constexpr double kSize = 520.0, kMargin = 60.0, kFont = 11.0;
constexpr const char* kCwColour = "#1f5fbf";
constexpr const char* kCcwColour = "#c0392b";

// marker: one run (with a tooltip `title`) or one legend sample (title empty) at (x, y) [px].
void marker(std::ostringstream& s, double x, double y, int shape, const char* col,
            const std::string& title = {}) {
  auto close = [&](const char* tag) {
    return title.empty() ? std::string("/>\n")
                         : "><title>" + title + "</title></" + std::string(tag) + ">\n";
  };
  const std::string paint =
      (shape == 0 ? std::string("fill=\"none\"") : std::string("fill=\"") + col + "\"") +
      " stroke=\"" + col + "\"";
  // Passes beyond the fourth reuse the filled shapes.
  switch (shape == 0 ? 0 : 1 + (shape - 1) % 4) {
    case 2:
      s << "<rect x=\"" << x - 3.5 << "\" y=\"" << y - 3.5 << "\" width=\"7\" height=\"7\" "
        << paint << close("rect");
      break;
    case 3:
      s << "<path d=\"M" << x << "," << y - 4.5 << " L" << x + 4 << "," << y + 3 << " L" << x - 4
        << "," << y + 3 << " Z\" " << paint << close("path");
      break;
    case 4:
      s << "<path d=\"M" << x << "," << y - 4.5 << " L" << x + 4.5 << "," << y << " L" << x << ","
        << y + 4.5 << " L" << x - 4.5 << "," << y << " Z\" " << paint << close("path");
      break;
    default:
      s << "<circle cx=\"" << x << "\" cy=\"" << y << "\" r=\"3.5\" " << paint << close("circle");
  }
}

// axes: frame, grid and labelled ticks of the symmetric view [-h, h] mm on both axes.
void axes(std::ostringstream& s, double h) {
  auto px = [&](double v) { return kMargin + kSize * (0.5 + 0.5 * v / h); };
  auto py = [&](double v) { return kMargin + kSize * (0.5 - 0.5 * v / h); };
  const double step = tick_step(2.0 * h);
  const double first = std::ceil(-h / step) * step;
  s << std::setprecision(6);
  for (double v = first; v <= h + 1e-9 * step; v += step) {
    const double t = std::fabs(v) < 1e-9 * step ? 0.0 : v;  // no "-0"
    const char* grid = t == 0.0 ? "#999" : "#e4e4e4";
    s << "<line x1=\"" << px(t) << "\" y1=\"" << kMargin << "\" x2=\"" << px(t) << "\" y2=\""
      << kMargin + kSize << "\" stroke=\"" << grid << "\"/>\n<line x1=\"" << kMargin << "\" y1=\""
      << py(t) << "\" x2=\"" << kMargin + kSize << "\" y2=\"" << py(t) << "\" stroke=\"" << grid
      << "\"/>\n<line x1=\"" << px(t) << "\" y1=\"" << kMargin + kSize << "\" x2=\"" << px(t)
      << "\" y2=\"" << kMargin + kSize + 5 << "\" stroke=\"black\"/>\n<line x1=\"" << kMargin - 5
      << "\" y1=\"" << py(t) << "\" x2=\"" << kMargin << "\" y2=\"" << py(t)
      << "\" stroke=\"black\"/>\n"
      << "<text x=\"" << px(t) << "\" y=\"" << kMargin + kSize + 17 << "\" text-anchor=\"middle\">"
      << t * 1e3 << "</text>\n<text x=\"" << kMargin - 8 << "\" y=\"" << py(t) + 4
      << "\" text-anchor=\"end\">" << t * 1e3 << "</text>\n";
  }
  s << "<rect x=\"" << kMargin << "\" y=\"" << kMargin << "\" width=\"" << kSize << "\" height=\""
    << kSize << "\" fill=\"none\" stroke=\"black\"/>\n<text x=\"" << kMargin + kSize / 2
    << "\" y=\"" << kMargin + kSize + 36 << "\" text-anchor=\"middle\">ex [mm]</text>\n"
    << "<text transform=\"translate(14," << kMargin + kSize / 2
    << ") rotate(-90)\" text-anchor=\"middle\">ey [mm]</text>\n";
}

// series_svg: every run of one set and its two centres of gravity (crosses).
void series_svg(std::ostringstream& s, const Series& se, double h) {
  auto px = [&](double v) { return kMargin + kSize * (0.5 + 0.5 * v / h); };
  auto py = [&](double v) { return kMargin + kSize * (0.5 - 0.5 * v / h); };
  for (const auto& run : *se.runs) {
    if (run.bumps) continue;
    marker(s, px(run.ex), py(run.ey), se.shape,
           run.direction == calib::Direction::kCw ? kCwColour : kCcwColour, se.label);
  }
  for (const calib::CentreOfGravity* g : {&se.cw, &se.ccw}) {
    const char* col = g == &se.cw ? kCwColour : kCcwColour;
    const double x = px(g->x), y = py(g->y);
    s << "<path d=\"M" << x - 7 << "," << y << " L" << x + 7 << "," << y << " M" << x << ","
      << y - 7 << " L" << x << "," << y + 7 << "\" stroke=\"" << col << "\" stroke-width=\"2\"/>\n";
  }
}

// legend_lines: one line a set ("before: r_cg cw 354 mm, ccw 352 mm").
std::vector<std::string> legend_lines(const std::vector<Series>& series) {
  std::vector<std::string> out;
  for (const Series& se : series) {
    std::ostringstream t;
    t << std::setprecision(4) << se.label << ": r_cg cw " << se.cw.r * 1e3 << " mm, ccw "
      << se.ccw.r * 1e3 << " mm";
    out.push_back(t.str());
  }
  return out;
}

}  // namespace

std::string umbmark_svg(const UmbmarkSimResult& r, const std::string& title) {
  std::vector<Series> series;
  const auto& p0 = r.passes.front().before;
  series.push_back({&p0.runs, p0.cw, p0.ccw, "before", 0});
  for (std::size_t i = 0; i < r.passes.size(); ++i) {
    const auto& a = r.passes[i].after;
    series.push_back(
        {&a.runs, a.cw, a.ccw, "after pass " + std::to_string(i + 1), static_cast<int>(i) + 1});
  }
  // Symmetric square view around the origin, in mm, big enough for every run.
  double h = 1e-3;
  for (const Series& s : series)
    for (const auto& run : *s.runs) h = std::max({h, std::fabs(run.ex), std::fabs(run.ey)});
  h *= 1.15;
  const std::string sub1 = "return errors ex, ey [mm] (truth - odometry, start frame)";
  const std::string sub2 =
      "blue cw, red ccw; open: before, filled: after each pass; crosses: centres of gravity";
  const std::vector<std::string> legend = legend_lines(series);
  // The canvas holds the plot, the legend to its right and the title lines, whatever their length.
  const double legend_x = kMargin + kSize + 30;
  double width = legend_x;
  for (const std::string& l : legend) width = std::max(width, legend_x + 16 + text_width(l, kFont));
  width =
      std::max({width, kMargin + text_width(title, 13), kMargin + text_width(sub2, kFont)}) + 10;
  std::ostringstream s;
  s << std::setprecision(6) << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << width
    << "\" height=\"" << kSize + 2 * kMargin << "\" font-family=\"sans-serif\" font-size=\""
    << kFont << "\">\n<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n<text x=\"" << kMargin
    << "\" y=\"18\" font-size=\"13\">" << xml_escape(title) << "</text>\n<text x=\"" << kMargin
    << "\" y=\"34\">" << sub1 << "</text>\n<text x=\"" << kMargin << "\" y=\"48\">" << sub2
    << "</text>\n";
  axes(s, h);
  for (std::size_t i = 0; i < series.size(); ++i) {
    series_svg(s, series[i], h);
    const double y = kMargin + 10 + 18 * static_cast<double>(i);
    marker(s, legend_x + 4, y - 4, series[i].shape, kCwColour);
    s << "<text x=\"" << legend_x + 16 << "\" y=\"" << y << "\">" << xml_escape(legend[i])
      << "</text>\n";
  }
  s << "</svg>\n";
  return s.str();
}

}  // namespace odo::analysis
