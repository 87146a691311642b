#include "odo/calibration/scaling.hpp"

#include <cmath>
#include <sstream>

namespace odo::calib {

Result<ScalingResult> scaling_error(double l_calc, double l_actual, double wheel_diameter) {
  auto bad = [](const char* field, double v, const char* range) {
    std::ostringstream m;
    m << field << " = " << v << " is outside the allowed range " << range;
    return make_error(Errc::kInvalidArgument, m.str());
  };
  if (!(std::isfinite(l_calc) && l_calc > 0)) return bad("calculated length", l_calc, "(0, inf) m");
  if (!(std::isfinite(l_actual) && l_actual > 0))
    return bad("measured length", l_actual, "(0, inf) m");
  if (!(std::isfinite(wheel_diameter) && wheel_diameter > 0))
    return bad("wheel diameter", wheel_diameter, "(0, inf) m");
  ScalingResult r;
  r.e_s = l_calc / l_actual;
  // More than 25 % off is a wrong measurement or wrong units, not a worn tyre.
  if (r.e_s < 0.8 || r.e_s > 1.25) return bad("E_s", r.e_s, "[0.8, 1.25] (check the units)");
  // L = N * pi * D / (n * Ce) for the same N: L_calc / L_actual = Dn / Da, so Da = Dn / E_s.
  r.wheel_diameter_new = wheel_diameter / r.e_s;
  return r;
}

}  // namespace odo::calib
