// Calibration store access for odometryd and odomctl: opening the configured medium, the JSON
// forms of a record (show / export / import, including `odomctl umbmark compute --json`) and
// applying a loaded record to the nominal kinematics.
#pragma once

#include <cstdint>
#include <ctime>
#include <memory>
#include <optional>
#include <string>
#include <string_view>

#include "odo/calibration/store.hpp"
#include "odo/hal/nv_storage.hpp"
#include "odo/hal/result.hpp"
#include "odo/odometry/kinematics.hpp"

namespace odo::fw {

// Where the store lives on a target (the Debian package creates /var/lib/odometryd).
inline constexpr const char* kDefaultCalibrationStore = "/var/lib/odometryd/calibration.bin";

// An open medium plus the A/B store on it.
struct OpenStore {
  std::unique_ptr<NvStorage> medium;
  std::optional<calib::CalibrationStore> store;
  std::string backend;  // "file", "nvmem" or "mtd"
};

// open_calibration_store: `backend` is auto | file | nvmem | mtd (auto: /dev/mtd* is MTD, a
// path under /sys/ or named nvmem is nvmem, anything else a regular file).
Result<OpenStore> open_calibration_store(const std::string& path, std::string_view backend);

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

// AppliedCalibration: what odometryd runs on after reading the store.
struct AppliedCalibration {
  KinematicParams params;      // nominal values with the stored corrections applied
  std::uint8_t state = 0;      // LoopSnapshot::calibration_state: 0 nominal, 1 ok, 2 corrupt
  std::uint64_t sequence = 0;  // of the record in use (0: none)
  std::string report;          // one line for the log
};

// apply_calibration: overrides c_l, c_r and, when stored, the effective wheelbase and the wheel
// diameter Dn*; an uncalibrated or corrupt store (or stored values Kinematics rejects) leaves
// the nominal values and says so.
AppliedCalibration apply_calibration(const KinematicParams& nominal,
                                     const Result<calib::LoadResult>& loaded,
                                     std::string_view where);

// read_and_apply: opens `path` (empty: no store configured), loads and applies.
AppliedCalibration read_and_apply(const KinematicParams& nominal, const std::string& path,
                                  std::string_view backend);

}  // namespace odo::fw
