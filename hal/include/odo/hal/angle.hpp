// Angle units: the code and its files are in radians; degrees appear only at the edges (reports
// for people, datasheet figures), converted with these two factors.
#pragma once

#include <numbers>

namespace odo {

inline constexpr double kDegPerRad = 180.0 / std::numbers::pi;  // [deg/rad]: rad * this = deg
inline constexpr double kRadPerDeg = std::numbers::pi / 180.0;  // [rad/deg]: deg * this = rad

}  // namespace odo
