// CalibrationStore: two record slots on a non-volatile medium, written alternately; the newer
// valid slot wins. A power cut at any instant leaves the previous or the new record loadable.
// Pure logic over odo::NvStorage (no file I/O here).
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>

#include "odo/calibration/record.hpp"
#include "odo/hal/nv_storage.hpp"

namespace odo::calib {

// What a load found. The numeric values are LoopSnapshot::calibration_state.
enum class StoreStatus : std::uint8_t {
  kUncalibrated = 0,  // nothing stored yet (or a reset marker): run on nominal values
  kOk = 1,            // a valid record
  kCorrupt = 2,       // the store held a record but no slot is valid: never use defaults silently
};

inline constexpr Choice<StoreStatus> kStoreStatusNames[] = {
    {StoreStatus::kUncalibrated, "uncalibrated"},
    {StoreStatus::kOk, "ok"},
    {StoreStatus::kCorrupt, "corrupt"}};

// status_name: s's spelling in kStoreStatusNames ("uncalibrated", "ok", "corrupt").
const char* status_name(StoreStatus s) noexcept;

struct SlotInfo {
  bool valid = false;
  bool blank = false;          // every byte erased (0xFF) or zero: never written
  std::uint64_t sequence = 0;  // when valid
  std::string problem;         // why not valid (empty when valid or blank)
};

struct LoadResult {
  StoreStatus status = StoreStatus::kUncalibrated;
  std::optional<CalibrationRecord> record;  // the newest valid record (also a reset marker)
  int slot = -1;                            // 0 (A) or 1 (B); -1 when no slot is valid
  std::array<SlotInfo, 2> slots;
  // Both slots' records (A, B) where valid: the newest and the one before it (the history
  // `odomctl calib history` lists and `calib rollback` restores).
  std::array<std::optional<CalibrationRecord>, 2> records;
  // describe: one line for people: status, sequence, slot, and for corrupt stores the reasons.
  std::string describe() const;
};

// Slot placement on a medium. Erase-block media: one slot per (group of) erase block(s); byte
// media: two slots of min(512, size/2) bytes.
struct StoreLayout {
  std::size_t slot_size = 0;
  std::array<std::size_t, 2> slot_offset{};
};

// plan_layout: slots for a medium; fails when it is too small for two records.
Result<StoreLayout> plan_layout(const NvGeometry& g);

class CalibrationStore {
 public:
  // create: plans the layout of `medium` (not owned; must outlive the store).
  static Result<CalibrationStore> create(NvStorage& medium);

  // load: reads both slots. Errors only for I/O failures; a damaged store is a LoadResult with
  // status kCorrupt. A store where at least one slot is blank and none is valid is
  // uncalibrated: the first save writes both slots, so a store that completed a save never
  // has a blank slot again.
  Result<LoadResult> load();

  // save: writes `r` (sequence assigned here) into the slot that does not hold the newest
  // valid record, verifies it by reading back, and returns the sequence number written. On a
  // store without a valid record both slots are written (A, then B). Validates `r` first.
  Result<std::uint64_t> save(CalibrationRecord r);

  // clear: saves a reset marker; the store then loads as uncalibrated (power-cut safe too).
  Result<std::uint64_t> clear();

  const StoreLayout& layout() const noexcept { return layout_; }

 private:
  CalibrationStore(NvStorage& m, StoreLayout l) : medium_(&m), layout_(l) {}
  Status write_slot(int slot, const std::vector<std::uint8_t>& bytes);
  Result<std::uint64_t> save_unchecked(CalibrationRecord r);

  NvStorage* medium_;
  StoreLayout layout_;
};

}  // namespace odo::calib
