// IcrFit: whether the self-calibration fits the skid-steer ICR offset x_ICR (issue 38), apart
// from selfcal.hpp so that the daemon's config can name the choice without the fit's headers.
#pragma once

#include <cstdint>

#include "odo/hal/choice.hpp"

namespace odo::calib {

// kFixed (default): the fit is over (c_L, c_R, b) with the ICR offset in use held (0: the plain
// arcs, bit for bit as before x_ICR existed). kFit: x_ICR is a 4th parameter with a prior at the
// value in use; for skid-steer bases (README "Self-calibration from fixes": when it is
// observable).
enum class IcrFit : std::uint8_t { kFixed = 0, kFit = 1 };
inline constexpr Choice<IcrFit> kIcrFitNames[] = {{IcrFit::kFixed, "fixed"}, {IcrFit::kFit, "fit"}};

}  // namespace odo::calib
