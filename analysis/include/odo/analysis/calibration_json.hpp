// The JSON forms of a calibration record: `calib show`, `calib export`, and what `calib import`
// accepts (the exchange format, a show object, or `odomctl umbmark compute --json`).
#pragma once

#include <ctime>
#include <string>
#include <string_view>

#include "odo/calibration/store.hpp"
#include "odo/hal/result.hpp"

namespace odo::analysis {

// show_json: the `calib show --json` object: status, sequence, slot, c_l, c_r, wheelbase,
// wheel_diameter, e_s (null when absent or not ok), provenance, detail.
std::string show_json(const calib::LoadResult& l);
// show_text: the same for people (lengths also in mm, time in UTC).
std::string show_text(const calib::LoadResult& l);
// export_json: a record in the exchange format {"format": "diffodom-calibration", ...}.
std::string export_json(const calib::CalibrationRecord& r);

// parse_calibration_json: a record from `text` in the exchange format, the `calib show --json`
// object (status must be "ok") or the output of `odomctl umbmark compute --json` (c_l, c_r,
// b_new, e_max_syst, n_cw, n_ccw, ...). `now` stamps records that carry no time. Errors name
// `source` and the field; ranges are checked with calib::validate_record().
Result<calib::CalibrationRecord> parse_calibration_json(std::string_view text,
                                                        std::string_view source, std::time_t now);

}  // namespace odo::analysis
