// Scaling error E_s (UMBmark report, Appendix B): the ratio of the distance the odometry
// computed on a straight run to the distance actually travelled (tape-measured).
#pragma once

#include "odo/hal/result.hpp"

namespace odo::calib {

struct ScalingResult {
  double e_s = 1.0;                 // E_s = L_calc / L_actual (Eq. B.1)
  double wheel_diameter_new = 0.0;  // corrected nominal diameter Dn* [m], see scaling_error()
};

// scaling_error: E_s from a straight run: L_calc [m] as computed by odometry with diameter Dn
// [m], L_actual [m] as measured. Lengths must be positive and finite, E_s within [0.8, 1.25].
// Dn* = Dn / E_s: the report prints Eq. B.2 as Dn* = E_s * Dn, which corrects in the wrong
// direction (a wheel larger than Dn makes L_actual > L_calc, E_s < 1, and needs Dn* > Dn).
Result<ScalingResult> scaling_error(double l_calc, double l_actual, double wheel_diameter);

}  // namespace odo::calib
