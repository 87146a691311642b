#include "odo/calibration/store.hpp"

#include <algorithm>
#include <string>
#include <vector>

#include "odo/hal/format.hpp"

namespace odo::calib {
namespace {

constexpr std::size_t kByteSlotMax = 512;

bool all_bytes(const std::vector<std::uint8_t>& b, std::uint8_t v) {
  return std::all_of(b.begin(), b.end(), [v](std::uint8_t x) { return x == v; });
}

std::size_t round_up(std::size_t v, std::size_t unit) {
  return (v + unit - 1) / unit * unit;
}

}  // namespace

const char* status_name(StoreStatus s) noexcept {
  // The table's names are string literals: their data() is NUL-terminated.
  return choice_name(kStoreStatusNames, s).data();
}

std::string LoadResult::describe() const {
  std::string m = status_name(status);
  if (record)
    m += ", sequence " + decimal_text(record->sequence) + (slot == 0 ? " in slot A" : " in slot B");
  if (record && record->cleared) m += " (reset marker)";
  if (status == StoreStatus::kCorrupt || (status == StoreStatus::kUncalibrated && !record)) {
    for (int i = 0; i < 2; ++i) {
      const SlotInfo& s = slots[static_cast<std::size_t>(i)];
      m += i == 0 ? "; slot A: " : "; slot B: ";
      m += s.valid ? "valid" : s.blank ? "blank" : s.problem.c_str();
    }
  }
  return m;
}

Result<StoreLayout> plan_layout(const NvGeometry& g) {
  StoreLayout l;
  const std::size_t unit = std::max<std::size_t>(g.write_unit, 1);
  if (g.erase_block > 0) {
    l.slot_size = round_up(round_up(kRecordV1Bytes, unit), g.erase_block);
  } else {
    l.slot_size = std::min(kByteSlotMax, g.size / 2) / unit * unit;
  }
  if (l.slot_size < kRecordV1Bytes || 2 * l.slot_size > g.size) {
    return make_error(Errc::kUnsupported,
                      "medium of " + decimal_text(g.size) + " bytes (erase block " +
                          decimal_text(g.erase_block) +
                          ") is too small for two calibration slots of at least " +
                          decimal_text(kRecordV1Bytes) + " bytes");
  }
  l.slot_offset = {0, l.slot_size};
  return l;
}

Result<CalibrationStore> CalibrationStore::create(NvStorage& medium) {
  auto l = plan_layout(medium.geometry());
  if (!l) return std::move(l).error();
  return CalibrationStore(medium, *l);
}

Result<LoadResult> CalibrationStore::load() {
  LoadResult out;
  std::array<std::optional<CalibrationRecord>, 2> rec;
  std::vector<std::uint8_t> buf(layout_.slot_size);
  for (std::size_t i = 0; i < 2; ++i) {
    SlotInfo& s = out.slots[i];
    Status st = medium_->read(layout_.slot_offset[i], buf);
    if (!st) {
      // An uncorrectable read (flash ECC) makes the slot invalid; anything else is an I/O error.
      if (st.error().code != Errc::kCorrupt) return std::move(st).error();
      s.problem = "unreadable: " + st.error().message;
      continue;
    }
    s.blank = all_bytes(buf, 0xFF) || all_bytes(buf, 0x00);
    if (s.blank) continue;
    auto r = decode_record(buf);
    if (!r) {
      s.problem = r.error().message;
      continue;
    }
    s.valid = true;
    s.sequence = r->sequence;
    rec[i] = std::move(r).value();
  }
  if (rec[0] || rec[1]) {
    // Newer wins; equal sequence numbers only come from the first save, which writes the same
    // record to both slots.
    out.slot = (!rec[0] || (rec[1] && rec[1]->sequence > rec[0]->sequence)) ? 1 : 0;
    const CalibrationRecord& win = *rec[static_cast<std::size_t>(out.slot)];
    out.status = win.cleared ? StoreStatus::kUncalibrated : StoreStatus::kOk;
    out.record = win;
    out.records = rec;
  } else if (out.slots[0].blank || out.slots[1].blank) {
    out.status = StoreStatus::kUncalibrated;  // never written, or its first save was cut
  } else {
    out.status = StoreStatus::kCorrupt;
  }
  return out;
}

Status CalibrationStore::write_slot(int slot, const std::vector<std::uint8_t>& bytes) {
  const NvGeometry g = medium_->geometry();
  const std::size_t off = layout_.slot_offset[static_cast<std::size_t>(slot)];
  std::vector<std::uint8_t> padded = bytes;
  padded.resize(round_up(bytes.size(), std::max<std::size_t>(g.write_unit, 1)), 0xFF);
  // A version-2 record (148 bytes) on a medium planned for version 1 (slots >= 108 bytes): never
  // write into the other slot.
  if (padded.size() > layout_.slot_size)
    return make_error(Errc::kUnsupported, "a record of " + std::to_string(bytes.size()) +
                                              " bytes does not fit a slot of " +
                                              std::to_string(layout_.slot_size) + " bytes");
  if (g.erase_block > 0) {
    if (auto s = medium_->erase(off, layout_.slot_size); !s) return s;
  }
  if (auto s = medium_->write(off, padded); !s) return s;
  // Read back: a medium that silently dropped the write must not be reported as saved.
  std::vector<std::uint8_t> check(padded.size());
  if (auto s = medium_->read(off, check); !s) return s;
  if (check != padded)
    return make_error(Errc::kIo, std::string("read-back of slot ") + (slot == 0 ? "A" : "B") +
                                     " differs from what was written");
  return Ok{};
}

Result<std::uint64_t> CalibrationStore::save_unchecked(CalibrationRecord r) {
  auto cur = load();
  if (!cur) return std::move(cur).error();
  if (cur->record) {
    r.sequence = cur->record->sequence + 1;
    auto bytes = encode_record(r);
    if (!bytes) return std::move(bytes).error();
    if (auto s = write_slot(1 - cur->slot, *bytes); !s) return std::move(s).error();
    return r.sequence;
  }
  // No valid record: write the same record to both slots, so that a finished save never leaves
  // a blank slot (which would make a later total loss look like "never written").
  r.sequence = 1;
  auto bytes = encode_record(r);
  if (!bytes) return std::move(bytes).error();
  for (int slot = 0; slot < 2; ++slot)
    if (auto s = write_slot(slot, *bytes); !s) return std::move(s).error();
  return r.sequence;
}

Result<std::uint64_t> CalibrationStore::save(CalibrationRecord r) {
  if (auto s = validate_record(r); !s) return std::move(s).error();
  r.cleared = false;
  return save_unchecked(std::move(r));
}

Result<std::uint64_t> CalibrationStore::clear() {
  CalibrationRecord r;
  r.cleared = true;
  r.method = "reset";
  return save_unchecked(r);
}

}  // namespace odo::calib
