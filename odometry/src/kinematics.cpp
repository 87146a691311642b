#include "odo/odometry/kinematics.hpp"

#include "odo/hal/field_range.hpp"

#include <cmath>
#include <numbers>
#include <optional>

namespace odo {
namespace {

// check_range: one field against its limit; on failure `bad` says which, as data.
bool check_range(std::optional<FieldRange>& bad, const char* field, const char* unit, double v,
                 Limit l) {
  if (l.contains(v)) return true;
  bad = FieldRange{field, v, l.lo, l.hi, unit};
  return false;
}

}  // namespace

Result<Kinematics> Kinematics::create(const KinematicParams& p) {
  using L = KinematicLimits;
  std::optional<FieldRange> bad;
  const bool ok = check_range(bad, "wheel_diameter", "m", p.wheel_diameter, L::kWheelDiameter) &&
                  check_range(bad, "counts_per_rev", "", p.counts_per_rev, L::kCountsPerRev) &&
                  check_range(bad, "gear_ratio", "", p.gear_ratio, L::kGearRatio) &&
                  check_range(bad, "wheelbase_nominal", "m", p.wheelbase_nominal, L::kWheelbase) &&
                  check_range(bad, "wheelbase", "m", p.wheelbase, L::kWheelbase) &&
                  check_range(bad, "c_l", "", p.c_l, L::kFactor) &&
                  check_range(bad, "c_r", "", p.c_r, L::kFactor) &&
                  check_range(bad, "x_icr", "m", p.x_icr, L::kXIcr);
  if (!ok) return range_error(std::move(*bad));
  return Kinematics(p);
}

double counts_per_metre(const KinematicParams& p) noexcept {
  return p.counts_per_rev * p.gear_ratio / (std::numbers::pi * p.wheel_diameter);
}

Kinematics::Kinematics(const KinematicParams& p) : p_(p) {
  c_m_ = std::numbers::pi * p.wheel_diameter / (p.gear_ratio * p.counts_per_rev);
  m_per_count_l_ = p.c_l * c_m_;
  m_per_count_r_ = p.c_r * c_m_;
  skid_ = p.x_icr != 0.0;
}

}  // namespace odo
