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
    if (auto d = choice_value<calib::Direction>(calib::kDirections, dir))
      r.direction = *d;
    else
      return csv.error("field 'direction' = '" + dir + "' must be " +
                       choice_join(calib::kDirections, " or "));
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
    s << choice_name(calib::kDirections, r.direction) << "," << std::setprecision(4) << r.ex << ","
      << r.ey << ",";
    if (r.etheta) s << std::setprecision(5) << *r.etheta;
    s << "," << (r.bumps ? 1 : 0) << "\n";
  }
  return s.str();
}

namespace {

// Series: one set of runs drawn in a panel with its own marker.
struct Series {
  const std::vector<calib::UmbmarkRun>* runs;
  calib::CentreOfGravity cw, ccw;
  std::string label;  // legend text before the colon, the runs' tooltip, the class "run NAME"
  std::string name;   // class of its markers: before, bumps, after-1 ..
  int shape;          // marker_svg shape
  bool filled;
  bool bumps;  // the extended-UMBmark runs (no centres of gravity: Eq. 3.2 leaves them out)
};

constexpr double kPanel = 400.0, kTop = 84.0, kLeft = 70.0, kFont = 11.0;
constexpr int kBumpShape = 10;  // four-pointed star, open: no pass uses it
constexpr const char* kCwColour = "#1f5fbf";
constexpr const char* kCcwColour = "#c0392b";

std::string paint(const Series& se, const char* col) {
  return std::string("fill=\"") + (se.filled ? col : "none") + "\" stroke=\"" + col +
         "\" class=\"run " + se.name + "\"";
}

// half_range: a symmetric view [-h, h] mm holding every run of the series, 15 % spare.
double half_range(const std::vector<Series>& series) {
  double h = 1e-3;
  for (const Series& s : series)
    for (const auto& run : *s.runs) h = std::max({h, std::fabs(run.ex), std::fabs(run.ey)});
  return 1.15e3 * h;
}

// panel_svg: the axes of one panel (equal scales: ex and ey are positions), every run of its
// series and the centres of gravity (crosses) of the plain runs.
void panel_svg(std::ostringstream& s, PlotFrame f, const std::string& title,
               const std::vector<Series>& series) {
  equal_scale(f);
  const double step = tick_step(f.x1 - f.x0);
  s << "<g class=\"panel\">\n<text x=\"" << f.left << "\" y=\"" << f.top - 8 << "\">"
    << xml_escape(title) << "</text>\n";
  axes_svg(s, f, step, step, "ex [mm]", "ey [mm]", kFont);
  for (const Series& se : series) {
    for (const auto& run : *se.runs) {
      if (run.bumps != se.bumps) continue;
      const char* col = run.direction == calib::Direction::kCw ? kCwColour : kCcwColour;
      marker_svg(s, se.shape, f.px(run.ex * 1e3), f.py(run.ey * 1e3), paint(se, col), se.label);
    }
    if (se.bumps) continue;
    for (const calib::CentreOfGravity* g : {&se.cw, &se.ccw}) {
      const char* col = g == &se.cw ? kCwColour : kCcwColour;
      const double x = f.px(g->x * 1e3), y = f.py(g->y * 1e3);
      s << "<path class=\"cg\" d=\"M" << x - 7 << "," << y << " L" << x + 7 << "," << y << " M" << x
        << "," << y - 7 << " L" << x << "," << y + 7 << "\" stroke=\"" << col
        << "\" stroke-width=\"2\"/>\n";
    }
  }
  s << "</g>\n";
}

// legend_line: "before: r_cg cw 354 mm, ccw 352 mm" (bump runs: how many).
std::string legend_line(const Series& se) {
  std::ostringstream t;
  if (se.bumps) {
    t << se.label << ": " << se.runs->size() << " (10 bumps each; not in the centres of gravity)";
  } else {
    t << std::setprecision(4) << se.label << ": r_cg cw " << se.cw.r * 1e3 << " mm, ccw "
      << se.ccw.r * 1e3 << " mm";
  }
  return t.str();
}

}  // namespace

std::string umbmark_svg(const UmbmarkSimResult& r, const std::string& title) {
  const auto& p0 = r.passes.front().before;
  std::vector<Series> before{{&p0.runs, p0.cw, p0.ccw, "before", "before", 0, false, false}};
  if (!r.bump_runs.empty())
    before.push_back({&r.bump_runs, {}, {}, "bump runs", "bumps", kBumpShape, false, true});
  std::vector<Series> after;
  for (std::size_t i = 0; i < r.passes.size(); ++i) {
    const auto& a = r.passes[i].after;
    const std::string k = std::to_string(i + 1);
    after.push_back({&a.runs, a.cw, a.ccw, "after pass " + k, "after-" + k,
                     static_cast<int>(i) % kMarkerShapes, true, false});
  }
  // Two panels, each on its own scale: the after-clusters are ten times tighter than the
  // before-clusters and would be a dot in their frame.
  const double hb = half_range(before), ha = half_range(after);
  const PlotFrame fb{kLeft, kTop, kPanel, kPanel, -hb, hb, -hb, hb};
  PlotFrame fa{0.0, kTop, kPanel, kPanel, -ha, ha, -ha, ha};
  fa.left = kLeft + kPanel + 20 + y_tick_room(fa, tick_step(2 * ha), kFont);
  const std::string sub1 = "return errors ex, ey [mm] (truth - odometry, start frame)";
  const std::string sub2 =
      "blue cw, red ccw; one marker a set; crosses: centres of gravity; each panel its own scale";
  std::vector<const Series*> all;
  for (const auto* v : {&before, &after})
    for (const Series& se : *v) all.push_back(&se);
  // The canvas holds both panels, the legend to their right and the title lines.
  const double legend_x = fa.left + kPanel + 30;
  double width = legend_x;
  for (const Series* se : all)
    width = std::max(width, legend_x + 16 + text_width(legend_line(*se), kFont));
  width = std::max({width, kLeft + text_width(title, 13), kLeft + text_width(sub2, kFont)}) + 10;
  std::ostringstream s;
  s << std::setprecision(6) << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << width
    << "\" height=\"" << kTop + kPanel + 50 << "\" font-family=\"sans-serif\" font-size=\"" << kFont
    << "\">\n<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n<text x=\"" << kLeft
    << "\" y=\"18\" font-size=\"13\">" << xml_escape(title) << "</text>\n<text x=\"" << kLeft
    << "\" y=\"34\">" << sub1 << "</text>\n<text x=\"" << kLeft << "\" y=\"48\">" << sub2
    << "</text>\n";
  panel_svg(s, fb, "before: the first pass's input (uncalibrated)", before);
  panel_svg(s, fa, "after each pass: the verification sets", after);
  for (std::size_t i = 0; i < all.size(); ++i) {
    const double y = kTop + 10 + 18 * static_cast<double>(i);
    const Series& se = *all[i];
    std::string legend_paint = paint(se, kCwColour);
    legend_paint = legend_paint.substr(0, legend_paint.find(" class="));
    marker_svg(s, se.shape, legend_x + 4, y - 4, legend_paint);
    s << "<text x=\"" << legend_x + 16 << "\" y=\"" << y << "\">" << xml_escape(legend_line(se))
      << "</text>\n";
  }
  s << "</svg>\n";
  return s.str();
}

}  // namespace odo::analysis
