// Kinematic parameters of a differential-drive base and the count -> distance conversion.
#pragma once

#include "odo/hal/result.hpp"

namespace odo {

// What the firmware believes about the robot. All lengths in metres.
struct KinematicParams {
  double wheel_diameter = 0.0;     // nominal wheel diameter Dn [m]
  double counts_per_rev = 0.0;     // encoder counts per motor revolution after quadrature (Ce)
  double gear_ratio = 1.0;         // motor revolutions per wheel revolution (n)
  double wheelbase_nominal = 0.0;  // nominal wheelbase [m], as designed
  double wheelbase = 0.0;          // effective wheelbase b used for integration [m] (UMBmark b_new)
  double c_l = 1.0;                // UMBmark correction factor of the left wheel (Eq. 6.33)
  double c_r = 1.0;                // UMBmark correction factor of the right wheel (Eq. 6.34)
  // Longitudinal offset of the instantaneous centre of rotation of a skid-steer base (x_ICR of
  // Mandow et al. 2007) [m], + ahead of the centre point: the centre slides sideways by
  // -x_icr * dtheta when the body turns by dtheta. 0 (the default) is the plain differential
  // drive, every output bit-identical to a base without it.
  double x_icr = 0.0;
};

// KinematicLimits: the allowed range of each parameter, written once: Kinematics::create and
// the config reader ([robot]) check against it. Wide enough for any wheeled base from a 30 mm
// toy to a 3 m vehicle but catch unit mistakes (mm instead of m, degrees instead of a factor).
struct KinematicLimits {
  static constexpr Limit kWheelDiameter{0.005, 5.0};  // [m]
  static constexpr Limit kCountsPerRev{1.0, 1e9};     // [counts]
  static constexpr Limit kGearRatio{1e-3, 1e4};
  static constexpr Limit kWheelbase{0.01, 20.0};  // nominal and effective [m]
  static constexpr Limit kFactor{0.5, 1.5};       // c_l, c_r
  // x_icr [m]: a few times the load's offset from the centre on a 4WD base (a 20 mm offset
  // gives ~60 mm); 2 m catches millimetres written for metres on any base up to 3 m.
  static constexpr Limit kXIcr{-2.0, 2.0};
};

// counts_per_metre: encoder counts per metre of nominal wheel travel, Ce * n / (pi * Dn)
// [counts/m] (the inverse of Kinematics::metres_per_count, for unvalidated parameters).
double counts_per_metre(const KinematicParams& p) noexcept;

// Validated parameters plus the derived per-count distances.
class Kinematics {
 public:
  // create: validates every field (finite, positive, factors within [0.5, 1.5], x_icr within
  // kXIcr) and derives
  // metres per count; the error names the field, its value and the allowed range.
  static Result<Kinematics> create(const KinematicParams& p);

  const KinematicParams& params() const noexcept { return p_; }
  // c_m of UMBmark Eq. 2.1 with the pi of a circumference: pi * Dn / (n * Ce) [m/count].
  double metres_per_count() const noexcept { return c_m_; }
  double metres_per_count_left() const noexcept { return m_per_count_l_; }   // c_L * c_m [m]
  double metres_per_count_right() const noexcept { return m_per_count_r_; }  // c_R * c_m [m]
  double wheelbase() const noexcept { return p_.wheelbase; }                 // b [m]
  double x_icr() const noexcept { return p_.x_icr; }  // longitudinal ICR offset [m], 0 = none
  // skid: x_icr != 0, kept as a flag so that the tick tests one byte (a compare of a double
  // with 0 is five instructions on x86-64).
  bool skid() const noexcept { return skid_; }

 private:
  explicit Kinematics(const KinematicParams& p);
  KinematicParams p_;
  double c_m_ = 0.0;
  double m_per_count_l_ = 0.0;
  double m_per_count_r_ = 0.0;
  bool skid_ = false;
};

}  // namespace odo
