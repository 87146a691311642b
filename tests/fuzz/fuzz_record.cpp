// Fuzz target: the calibration record decoder (odo::calib::decode_record) and the A/B store
// loader on a medium holding the fuzz bytes (odo::calib::CalibrationStore::load on SimNvStorage).
// Then what odometryd does with the loaded store (odo::fw::apply_calibration on the reference
// robot). Properties: never crashes or overflows (ASan, UBSan); a decoded record re-encodes and
// decodes to the same record (nothing invented, nothing lost); the parameters odometryd would
// run on always form valid Kinematics; it reports "calibrated" only for a store that loaded as
// ok, and an error exactly for a corrupt store or a stored record outside its limits.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <span>

#include "fuzz_check.hpp"
#include "odo/analysis/calibration_json.hpp"
#include "odo/calibration/record.hpp"
#include "odo/calibration/store.hpp"
#include "odo/firmware/calibration_store.hpp"
#include "odo/odometry/kinematics.hpp"
#include "odo/sim/sim_nv_storage.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using odo::fuzz::require;
  const std::span<const std::uint8_t> bytes(data, size);
  auto r = odo::calib::decode_record(bytes);
  if (r) {
    auto again = odo::calib::encode_record(*r);
    require(again.ok(), "a decoded record does not encode:", again ? "" : again.error().message);
    auto back = odo::calib::decode_record(*again);
    require(back.ok() && *back == *r, "decode(encode(decode(x))) differs from decode(x)");
  } else {
    require(r.error().code == odo::Errc::kCorrupt, "a rejected record is not reported corrupt");
  }

  // The same bytes as the content of a 1 KiB EEPROM (two 512-byte slots).
  odo::sim::SimNvStorage medium(odo::sim::SimMedium::kEeprom, 1024, 1, 16);
  std::size_t n = std::min<std::size_t>(size, 1024);
  require(medium.write(0, bytes.first(n)).ok(), "simulated medium refused a write");
  auto store = odo::calib::CalibrationStore::create(medium);
  require(store.ok(), "1 KiB store not created");
  auto loaded = store->load();
  require(loaded.ok(), "load of a readable medium failed");
  // The reference robot: 0.15 m wheels, 2048 counts, 16:1 gear, 0.34 m wheelbase.
  const odo::KinematicParams nominal{0.15, 2048, 16, 0.34, 0.34, 1.0, 1.0};
  const odo::fw::AppliedCalibration a = odo::fw::apply_calibration(nominal, loaded, "fuzz");
  require(odo::Kinematics::create(a.params).ok(), "odometryd would run on invalid kinematics");
  require(a.state != odo::calib::StoreStatus::kOk || loaded->status == odo::calib::StoreStatus::kOk,
          "calibrated state from a store that did not load as ok");
  // The error state (2): always for a corrupt store and for a stored record outside its limits
  // (Kinematics may reject a few more), never for an uncalibrated store.
  const bool ok = loaded->status == odo::calib::StoreStatus::kOk;
  require(loaded->status != odo::calib::StoreStatus::kCorrupt ||
              a.state == odo::calib::StoreStatus::kCorrupt,
          "corrupt store not reported as an error");
  require(!ok || odo::calib::validate_record(*loaded->record).ok() ||
              a.state == odo::calib::StoreStatus::kCorrupt,
          "out-of-range record not reported as an error");
  require(loaded->status != odo::calib::StoreStatus::kUncalibrated ||
              a.state == odo::calib::StoreStatus::kUncalibrated,
          "uncalibrated store not reported as uncalibrated");
  require(a.state != odo::calib::StoreStatus::kOk || a.params.c_l == loaded->record->c_l,
          "calibrated state without the stored factors");
  return 0;
}
