#include "odo/analysis/replay.hpp"

#include <optional>
#include <sstream>

#include "odo/analysis/csv.hpp"
#include "odo/odometry/count_delta.hpp"

namespace odo::analysis {

namespace {

// Row: one parsed data row.
struct Row {
  double t = 0.0;
  std::int64_t left = 0, right = 0;
  double gyro_z = 0.0;
};

// Fuser: the loop's integration of one interval, with or without the gyro's fusion.
class Fuser {
 public:
  Fuser(const Kinematics& k, const ReplayGyro* g) : odom_(k), k_(k), g_(g) {}
  Status step(std::int64_t dl, std::int64_t dr, double dt, double gyro_z) {
    if (g_ == nullptr) {
      odom_.update(dl, dr, dt);
      return Ok{};
    }
    if (!fusion_) {
      // The first interval's length is the log's tick (the loop's period).
      GyrodometryParams p = g_->params;
      p.tick = dt;
      p.heading_quantum =
          (k_.metres_per_count_left() + k_.metres_per_count_right()) / k_.wheelbase();
      auto f = Gyrodometry::create(p);
      if (!f) return std::move(f).error();
      fusion_.emplace(std::move(f).value());
    }
    FusionInput in;
    in.dt = dt;
    in.d_left = static_cast<double>(dl) * k_.metres_per_count_left();
    in.d_right = static_cast<double>(dr) * k_.metres_per_count_right();
    in.wheelbase = k_.wheelbase();
    in.gyro.rate_z = gyro_z;
    in.gyro.samples = 1;
    const FusedTick f = fusion_->step(in);
    odom_.update_fused(dl, dr, dt, f.dtheta, f.ds);
    return Ok{};
  }
  void finish(ReplayResult& r) const {
    r.pose = odom_.pose();
    r.distance = odom_.distance();
    r.fused = fusion_.has_value();
    if (fusion_) r.fusion = fusion_->counters();
  }

 private:
  Odometry odom_;
  Kinematics k_;
  const ReplayGyro* g_;
  std::optional<Gyrodometry> fusion_;
};

// read_row: one data row; errors name the file, the line and the field.
Result<Row> read_row(const CsvReader& csv, const std::vector<std::string>& f,
                     const std::vector<int>& cols, int bits) {
  if (f.size() != csv.columns()) {
    return csv.error("expected " + std::to_string(csv.columns()) + " fields, found " +
                     std::to_string(f.size()));
  }
  Row row;
  auto t = csv.parse_double(f[cols[0]], "t");
  if (!t) return std::move(t).error();
  row.t = *t;
  auto raw_l = csv.parse_int64(f[cols[1]], "left");
  if (!raw_l) return std::move(raw_l).error();
  auto raw_r = csv.parse_int64(f[cols[2]], "right");
  if (!raw_r) return std::move(raw_r).error();
  auto l = normalise_reading(*raw_l, bits);
  if (!l) return csv.error("field 'left': " + l.error().message);
  auto r = normalise_reading(*raw_r, bits);
  if (!r) return csv.error("field 'right': " + r.error().message);
  row.left = *l;
  row.right = *r;
  if (cols[3] >= 0) {
    auto g = csv.parse_double(f[cols[3]], "gyro_z");  // NaN, inf and empty are errors
    if (!g) return std::move(g).error();
    row.gyro_z = *g;
  }
  return row;
}

}  // namespace

Result<ReplayResult> replay_ticks(std::istream& in, const std::string& source, const Kinematics& k,
                                  int bits) {
  ReplayGyro off;
  off.use = false;
  return replay_ticks(in, source, k, bits, off);
}

Result<ReplayResult> replay_ticks(std::istream& in, const std::string& source, const Kinematics& k,
                                  int bits, const ReplayGyro& gyro) {
  if (auto s = check_counter_bits(bits); !s) return std::move(s).error();
  CsvReader csv(in, source);
  auto cols = csv.header({"t", "left", "right"}, {"gyro_z"});
  if (!cols) return std::move(cols).error();
  Fuser fuser(k, gyro.use && (*cols)[3] >= 0 ? &gyro : nullptr);
  ReplayResult r;
  std::vector<std::string> f;
  Row prev;
  while (csv.next(f)) {
    auto row = read_row(csv, f, *cols, bits);
    if (!row) return std::move(row).error();
    if (r.samples > 0) {
      if (row->t < prev.t) {
        std::ostringstream m;
        m << "field 't' = " << row->t << " s goes backwards (previous row: " << prev.t << " s)";
        return csv.error(m.str());
      }
      auto s = fuser.step(wrap_delta(prev.left, row->left, bits),
                          wrap_delta(prev.right, row->right, bits), row->t - prev.t, row->gyro_z);
      if (!s) return csv.error(s.error().message);
    }
    prev = *row;
    ++r.samples;
  }
  fuser.finish(r);
  return r;
}

}  // namespace odo::analysis
