// Angle units: the code and its files are in radians; degrees appear only at the edges (reports
// for people, datasheet figures), converted with these two factors; and the one wrap of an angle
// into (-pi, pi] (odometry keeps heading cumulative; the protocol and displays wrap it).
#pragma once

#include <cmath>
#include <numbers>

namespace odo {

inline constexpr double kDegPerRad = 180.0 / std::numbers::pi;  // [deg/rad]: rad * this = deg
inline constexpr double kRadPerDeg = std::numbers::pi / 180.0;  // [rad/deg]: deg * this = rad

// wrap_angle: maps any angle [rad] into (-pi, pi].
inline double wrap_angle(double a) noexcept {
  constexpr double kPi = std::numbers::pi;
  double r = std::remainder(a, 2.0 * kPi);  // in [-pi, pi], exact (no rounding)
  if (r <= -kPi) r += 2.0 * kPi;            // -pi maps to +pi
  return r;
}

}  // namespace odo
