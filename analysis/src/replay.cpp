#include "odo/analysis/replay.hpp"

#include <sstream>

#include "odo/analysis/csv.hpp"
#include "odo/odometry/count_delta.hpp"

namespace odo::analysis {

Result<ReplayResult> replay_ticks(std::istream& in, const std::string& source, const Kinematics& k,
                                  int bits) {
  if (auto s = check_counter_bits(bits); !s) return std::move(s).error();
  CsvReader csv(in, source);
  auto cols = csv.header({"t", "left", "right"});
  if (!cols) return std::move(cols).error();
  const int ct = (*cols)[0], cl = (*cols)[1], cr = (*cols)[2];

  Odometry odom(k);
  ReplayResult r;
  std::vector<std::string> f;
  double prev_t = 0.0;
  std::int64_t prev_l = 0, prev_r = 0;
  while (csv.next(f)) {
    if (f.size() != csv.columns()) {
      return csv.error("expected " + std::to_string(csv.columns()) + " fields, found " +
                       std::to_string(f.size()));
    }
    auto t = csv.parse_double(f[ct], "t");
    if (!t) return std::move(t).error();
    auto raw_l = csv.parse_int64(f[cl], "left");
    if (!raw_l) return std::move(raw_l).error();
    auto raw_r = csv.parse_int64(f[cr], "right");
    if (!raw_r) return std::move(raw_r).error();
    auto l = normalise_reading(*raw_l, bits);
    if (!l) return csv.error("field 'left': " + l.error().message);
    auto rr = normalise_reading(*raw_r, bits);
    if (!rr) return csv.error("field 'right': " + rr.error().message);
    if (r.samples > 0) {
      if (*t < prev_t) {
        std::ostringstream m;
        m << "field 't' = " << *t << " s goes backwards (previous row: " << prev_t << " s)";
        return csv.error(m.str());
      }
      odom.update(wrap_delta(prev_l, *l, bits), wrap_delta(prev_r, *rr, bits), *t - prev_t);
    }
    prev_t = *t;
    prev_l = *l;
    prev_r = *rr;
    ++r.samples;
  }
  r.pose = odom.pose();
  r.distance = odom.distance();
  return r;
}

}  // namespace odo::analysis
