#include "odo/odometry/kinematics.hpp"

#include "odo/hal/field_range.hpp"

#include <cmath>
#include <numbers>
#include <sstream>

namespace odo {
namespace {

// check_range: one field against [lo, hi]; writes a message naming field, value and range.
bool check_range(std::ostringstream& msg, const char* field, const char* unit, double v, double lo,
                 double hi) {
  if (std::isfinite(v) && v >= lo && v <= hi) return true;
  msg << range_message({field, v, lo, hi, unit});
  return false;
}

}  // namespace

Result<Kinematics> Kinematics::create(const KinematicParams& p) {
  std::ostringstream msg;
  // Ranges are wide enough for any wheeled base from a 30 mm toy to a 3 m vehicle but catch
  // unit mistakes (mm instead of m, degrees instead of a factor).
  const bool ok = check_range(msg, "wheel_diameter", "m", p.wheel_diameter, 0.005, 5.0) &&
                  check_range(msg, "counts_per_rev", "", p.counts_per_rev, 1.0, 1e9) &&
                  check_range(msg, "gear_ratio", "", p.gear_ratio, 1e-3, 1e4) &&
                  check_range(msg, "wheelbase_nominal", "m", p.wheelbase_nominal, 0.01, 20.0) &&
                  check_range(msg, "wheelbase", "m", p.wheelbase, 0.01, 20.0) &&
                  check_range(msg, "c_l", "", p.c_l, 0.5, 1.5) &&
                  check_range(msg, "c_r", "", p.c_r, 0.5, 1.5);
  if (!ok) return make_error(Errc::kInvalidArgument, msg.str());
  return Kinematics(p);
}

double counts_per_metre(const KinematicParams& p) noexcept {
  return p.counts_per_rev * p.gear_ratio / (std::numbers::pi * p.wheel_diameter);
}

Kinematics::Kinematics(const KinematicParams& p) : p_(p) {
  c_m_ = std::numbers::pi * p.wheel_diameter / (p.gear_ratio * p.counts_per_rev);
  m_per_count_l_ = p.c_l * c_m_;
  m_per_count_r_ = p.c_r * c_m_;
}

}  // namespace odo
