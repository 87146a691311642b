#include <cmath>
#include <numbers>
#include <sstream>

#include "odo/analysis/csv.hpp"
#include "odo/analysis/selfcal_tools.hpp"
#include "odo/loop/recording_encoder.hpp"
#include "odo/odometry/count_delta.hpp"

namespace odo::analysis {
namespace {

constexpr double kTwoPi = 2.0 * std::numbers::pi;

// RowSource: the current CSV row as an encoder reading.
class RowSource final : public EncoderSource {
 public:
  explicit RowSource(int bits) : bits_(bits) {}
  EncoderSample read(TimeNs) noexcept override { return s; }
  int counter_bits() const noexcept override { return bits_; }
  EncoderSample s;

 private:
  int bits_;
};

// optional_number: an empty field is `def`; else the number, which must lie in (lo, hi].
Result<double> ranged(const CsvReader& csv, const std::string& text, std::string_view field,
                      double def, double lo, double hi, const char* unit) {
  if (text.empty()) return def;
  auto v = csv.parse_double(text, field);
  if (!v) return v;
  if (!(*v > lo && *v <= hi)) {
    std::ostringstream m;
    m << "field '" << field << "' = " << *v << " is outside the allowed range (" << lo << ", " << hi
      << "] " << unit;
    return csv.error(m.str());
  }
  return v;
}

}  // namespace

Result<std::vector<calib::CountSegment>> read_count_segments(std::istream& in,
                                                             const std::string& source,
                                                             const Kinematics& k, int bits,
                                                             LogSpan* span) {
  if (auto s = check_counter_bits(bits); !s) return std::move(s).error();
  auto limits = calib::recorder_limits(k);
  if (!limits) return std::move(limits).error();
  CsvReader csv(in, source);
  auto cols = csv.header({"t", "left", "right"}, {"gyro_z"});
  if (!cols) return std::move(cols).error();
  const int ct = (*cols)[0], cl = (*cols)[1], cr = (*cols)[2];
  RowSource src(bits);
  loop::SegmentRing ring(64);
  loop::RecordingEncoder rec(src, *limits, ring);
  std::vector<calib::CountSegment> out;
  calib::CountSegment seg;
  std::vector<std::string> f;
  double prev_t = -HUGE_VAL;
  while (csv.next(f)) {
    if (f.size() != csv.columns())
      return csv.error("expected " + std::to_string(csv.columns()) + " fields, found " +
                       std::to_string(f.size()));
    auto t = csv.parse_double(f[ct], "t");
    if (!t) return std::move(t).error();
    if (*t < prev_t) {
      std::ostringstream m;
      m << "field 't' = " << *t << " s goes backwards (previous row: " << prev_t << " s)";
      return csv.error(m.str());
    }
    if (span != nullptr) {
      if (prev_t == -HUGE_VAL) span->first = from_seconds(*t);
      span->last = from_seconds(*t);
    }
    prev_t = *t;
    auto raw_l = csv.parse_int64(f[cl], "left");
    if (!raw_l) return std::move(raw_l).error();
    auto raw_r = csv.parse_int64(f[cr], "right");
    if (!raw_r) return std::move(raw_r).error();
    auto l = normalise_reading(*raw_l, bits);
    if (!l) return csv.error("field 'left': " + l.error().message);
    auto r = normalise_reading(*raw_r, bits);
    if (!r) return csv.error("field 'right': " + r.error().message);
    src.s = EncoderSample{*l, *r, from_seconds(*t), 0, {}};
    rec.read(0);
    while (ring.pop(seg)) out.push_back(seg);
  }
  rec.flush();
  while (ring.pop(seg)) out.push_back(seg);
  return out;
}

Result<std::vector<calib::PoseFix>> read_fixes(std::istream& in, const std::string& source,
                                               const FixDefaults& d) {
  CsvReader csv(in, source);
  auto cols = csv.header({"t", "x", "y"}, {"theta", "sigma_xy", "sigma_theta"});
  if (!cols) return std::move(cols).error();
  const std::vector<int>& c = *cols;
  std::vector<calib::PoseFix> out;
  std::vector<std::string> f;
  while (csv.next(f)) {
    if (f.size() != csv.columns())
      return csv.error("expected " + std::to_string(csv.columns()) + " fields, found " +
                       std::to_string(f.size()));
    auto field = [&](int i) {
      return c[static_cast<std::size_t>(i)] < 0
                 ? std::string()
                 : f[static_cast<std::size_t>(c[static_cast<std::size_t>(i)])];
    };
    calib::PoseFix p;
    auto t = csv.parse_double(field(0), "t");
    if (!t) return std::move(t).error();
    if (!out.empty() && from_seconds(*t) <= out.back().t) {
      std::ostringstream m;
      m << "field 't' = " << *t << " s is not after the previous fix's ("
        << to_seconds(out.back().t) << " s)";
      return csv.error(m.str());
    }
    p.t = from_seconds(*t);
    auto x = csv.parse_double(field(1), "x");
    if (!x) return std::move(x).error();
    auto y = csv.parse_double(field(2), "y");
    if (!y) return std::move(y).error();
    p.x = *x;
    p.y = *y;
    if (!field(3).empty()) {
      auto th = csv.parse_double(field(3), "theta");
      if (!th) return std::move(th).error();
      // A heading beyond a whole turn is not a wrapped angle in radians: most likely degrees.
      if (std::fabs(*th) > kTwoPi) {
        std::ostringstream m;
        m << "field 'theta' = " << *th << " is outside the allowed range [-" << kTwoPi << ", "
          << kTwoPi << "] rad (headings are in radians; this looks like degrees)";
        return csv.error(m.str());
      }
      p.theta = *th;
    }
    auto sxy = ranged(csv, field(4), "sigma_xy", d.sigma_xy, 0.0, 10.0, "m");
    if (!sxy) return std::move(sxy).error();
    auto sth = ranged(csv, field(5), "sigma_theta", d.sigma_theta, 0.0, 3.15, "rad");
    if (!sth) return std::move(sth).error();
    p.sigma_xy = *sxy;
    p.sigma_theta = *sth;
    out.push_back(p);
  }
  if (out.size() < 2)
    return make_error(Errc::kParse, source + ": at least two fixes are needed, found " +
                                        std::to_string(out.size()));
  return out;
}

}  // namespace odo::analysis
