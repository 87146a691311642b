#include "odo/calibration/scaling.hpp"

#include <cmath>

#include "odo/calibration/record.hpp"

namespace odo::calib {

Result<ScalingResult> scaling_error(double l_calc, double l_actual, double wheel_diameter) {
  auto positive = [](double v) { return std::isfinite(v) && v > 0; };
  if (!positive(l_calc)) return range_error(positive_range("calculated length", l_calc, "m"));
  if (!positive(l_actual)) return range_error(positive_range("measured length", l_actual, "m"));
  if (!positive(wheel_diameter))
    return range_error(positive_range("wheel diameter", wheel_diameter, "m"));
  ScalingResult r;
  r.e_s = l_calc / l_actual;
  // More than 25 % off is a wrong measurement or wrong units, not a worn tyre.
  using L = RecordLimits;  // the E_s a calibration record may hold
  if (r.e_s < L::kScalingMin || r.e_s > L::kScalingMax) {
    FieldRange e{"E_s", r.e_s, L::kScalingMin, L::kScalingMax};
    e.note = "(check the units)";
    return range_error(std::move(e));
  }
  // L = N * pi * D / (n * Ce) for the same N: L_calc / L_actual = Dn / Da, so Da = Dn / E_s.
  r.wheel_diameter_new = wheel_diameter / r.e_s;
  return r;
}

}  // namespace odo::calib
