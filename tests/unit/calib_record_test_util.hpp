// Shared by the calibration record tests of versions 2 and 3: sample records, little-endian
// reads, the bit-flip sweep, a flag set on a record too short for its fields, and the record in
// the store's other slot.
#pragma once

#include <gtest/gtest.h>

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "odo/calibration/record.hpp"
#include "odo/calibration/store.hpp"
#include "odo/hal/crc.hpp"
#include "odo/sim/sim_nv_storage.hpp"

namespace odo::calib::test {

inline CalibrationRecord umbmark_record() {
  CalibrationRecord r;
  r.c_l = 0.99925;
  r.c_r = 1.00075;
  r.wheelbase = 0.33702;
  r.time = 1795000000;
  r.method = "umbmark";
  r.runs = 10;
  return r;
}

inline CalibrationRecord online_record() {
  CalibrationRecord r = umbmark_record();
  r.method = "online";
  r.runs = 0;
  r.fit = FixFitProvenance{19, 2, 0.76, 3.2e-5, 3.1e-5, 1.04e-4};
  return r;
}

// le: the n-byte little-endian value at `off`.
inline std::uint64_t le(const std::vector<std::uint8_t>& b, std::size_t off, int n) {
  std::uint64_t v = 0;
  for (int i = 0; i < n; ++i) v |= static_cast<std::uint64_t>(b[off + i]) << (8 * i);
  return v;
}

// expect_every_bit_flip_detected: no single flipped bit of `b` decodes.
inline void expect_every_bit_flip_detected(const std::vector<std::uint8_t>& b) {
  for (std::size_t byte = 0; byte < b.size(); ++byte)
    for (int bit = 0; bit < 8; ++bit) {
      auto c = b;
      c[byte] ^= static_cast<std::uint8_t>(1U << bit);
      ASSERT_FALSE(decode_record(c)) << "byte " << byte << " bit " << bit;
    }
}

// expect_flag_needs_fields: `flag` (in flag byte 16) set on the record b, whose CRC is
// recomputed: corrupt, with `needle` in the message.
inline void expect_flag_needs_fields(std::vector<std::uint8_t> b, std::uint8_t flag,
                                     const std::string& needle) {
  b[16] |= flag;
  const std::size_t at = b.size() - 4;
  const std::uint32_t crc = crc32(std::span<const std::uint8_t>(b.data(), at));
  for (int i = 0; i < 4; ++i) b[at + i] = static_cast<std::uint8_t>(crc >> (8 * i));
  auto d = decode_record(b);
  ASSERT_FALSE(d);
  EXPECT_NE(d.error().message.find(needle), std::string::npos) << d.error().message;
}

// other_slot: the record in the slot of a 1 KiB EEPROM store (slots of 512 bytes) that `l` did
// not load from.
inline Result<CalibrationRecord> other_slot(sim::SimNvStorage& medium, const LoadResult& l) {
  std::vector<std::uint8_t> other(512);
  EXPECT_TRUE(medium.read(l.slot == 0 ? 512 : 0, other));
  return decode_record(other);
}

}  // namespace odo::calib::test
