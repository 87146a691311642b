// The calibration store as odometryd uses it: opening the configured medium and applying a
// loaded record to the nominal kinematics (at start and on every SIGHUP).
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>

#include "odo/calibration/store.hpp"
#include "odo/firmware/config.hpp"
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

// open_calibration_store: the medium `backend` (kAuto: /dev/mtd* is MTD, a path under /sys/ or
// named nvmem is nvmem, anything else a regular file).
Result<OpenStore> open_calibration_store(const std::string& path, NvBackend backend);

// AppliedCalibration: what odometryd runs on after reading the store.
struct AppliedCalibration {
  KinematicParams params;  // nominal values with the stored corrections applied
  calib::StoreStatus state = calib::StoreStatus::kUncalibrated;  // of the store; kCorrupt also
                                                                 // when it cannot be read
  std::uint64_t sequence = 0;                                    // of the record in use (0: none)
  std::string report;                                            // one line for the log
};

// apply_calibration: overrides c_l, c_r and, when stored, the effective wheelbase and the wheel
// diameter Dn*; an uncalibrated or corrupt store (or stored values Kinematics rejects) leaves
// the nominal values and says so.
AppliedCalibration apply_calibration(const KinematicParams& nominal,
                                     const Result<calib::LoadResult>& loaded,
                                     std::string_view where);

// read_and_apply: opens `path` (empty: no store configured), loads and applies.
AppliedCalibration read_and_apply(const KinematicParams& nominal, const std::string& path,
                                  NvBackend backend);

}  // namespace odo::fw
