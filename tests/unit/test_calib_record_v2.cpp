// Calibration record version 2: the provenance of a self-calibration fit (issue 18), and that
// version-1 records and media keep working.
#include <gtest/gtest.h>

#include <bit>
#include <string>

#include "calib_record_test_util.hpp"
#include "odo/calibration/record.hpp"
#include "odo/calibration/store.hpp"
#include "odo/hal/crc.hpp"
#include "odo/sim/sim_nv_storage.hpp"

namespace odo::calib {
namespace {

using test::le;
using test::online_record;
using test::umbmark_record;

TEST(CalibRecordV2, WithoutFitStillVersionOne) {
  auto b = encode_record(umbmark_record());
  ASSERT_TRUE(b);
  EXPECT_EQ(b->size(), kRecordV1Bytes);
  EXPECT_EQ(le(*b, 4, 2), 1U);
  EXPECT_EQ(le(*b, 6, 2), 108U);
}

TEST(CalibRecordV2, ByteLayoutAndRoundTrip) {
  const CalibrationRecord r = online_record();
  auto b = encode_record(r);
  ASSERT_TRUE(b) << b.error().message;
  ASSERT_EQ(b->size(), kRecordV2Bytes);
  EXPECT_EQ(le(*b, 4, 2), 2U);      // version
  EXPECT_EQ(le(*b, 6, 2), 148U);    // length
  EXPECT_EQ(le(*b, 16, 4), 0x42U);  // flags: wheelbase (bit 1) + fit (bit 6)
  EXPECT_EQ(le(*b, 104, 4), 19U);
  EXPECT_EQ(le(*b, 108, 4), 2U);
  EXPECT_EQ(le(*b, 112, 8), std::bit_cast<std::uint64_t>(0.76));
  EXPECT_EQ(le(*b, 136, 8), std::bit_cast<std::uint64_t>(1.04e-4));
  EXPECT_EQ(le(*b, 144, 4), crc32(std::span<const std::uint8_t>(b->data(), 144)));
  auto d = decode_record(*b);
  ASSERT_TRUE(d) << d.error().message;
  EXPECT_EQ(*d, r);
  // A version-1 reader checks version >= 1, length >= 108 and the CRC at length - 4, then reads
  // the fixed offsets below 104: those bytes are the version-1 encoding of the same values
  // (only version, length and the new flag bit differ).
  CalibrationRecord v1 = r;
  v1.fit.reset();
  auto b1 = encode_record(v1);
  ASSERT_TRUE(b1);
  for (std::size_t i = 8; i < 104; ++i)
    if (i != 16) {
      EXPECT_EQ((*b)[i], (*b1)[i]) << "byte " << i;
    }
}

TEST(CalibRecordV2, EveryBitFlipDetectedAndFlagNeedsTheFields) {
  auto b = encode_record(online_record());
  ASSERT_TRUE(b);
  test::expect_every_bit_flip_detected(*b);
  // The fit flag on a 108-byte version-1 record (CRC recomputed): corrupt, named.
  auto v1 = encode_record(umbmark_record());
  ASSERT_TRUE(v1);
  test::expect_flag_needs_fields(*v1, 0x40, "fit fields");
}

TEST(CalibRecordV2, ValidationNamesTheFitField) {
  CalibrationRecord r = online_record();
  r.fit->sigma_c_r = -1.0;
  auto s = validate_record(r);
  ASSERT_FALSE(s);
  EXPECT_NE(s.error().message.find("sigma_c_r"), std::string::npos);
}

TEST(CalibRecordV2, StoreKeepsTheOldRecordAndRefusesSmallSlots) {
  // 1 KiB EEPROM: slots of 512 bytes. An UMBmark record (v1) first, then an online one (v2):
  // the newest loads with its provenance, the other slot still holds the v1 record.
  sim::SimNvStorage big(sim::SimMedium::kEeprom, 1024, 0, 16);
  auto store = CalibrationStore::create(big);
  ASSERT_TRUE(store);
  ASSERT_TRUE(store->save(umbmark_record()));
  ASSERT_TRUE(store->save(online_record()));
  auto l = store->load();
  ASSERT_TRUE(l);
  ASSERT_TRUE(l->record);
  EXPECT_EQ(l->record->method, "online");
  ASSERT_TRUE(l->record->fit);
  EXPECT_EQ(l->record->fit->fixes_rejected, 2U);
  EXPECT_TRUE(l->slots[0].valid && l->slots[1].valid);
  auto old = test::other_slot(big, *l);
  ASSERT_TRUE(old);
  EXPECT_EQ(old->method, "umbmark");
  EXPECT_FALSE(old->fit);
  // 256-byte EEPROM: slots of 128 bytes hold v1 records but not the 148 of v2. The save is
  // refused (nothing written into the other slot) and the old record still loads.
  sim::SimNvStorage small(sim::SimMedium::kEeprom, 256, 0, 16);
  auto s2 = CalibrationStore::create(small);
  ASSERT_TRUE(s2);
  ASSERT_TRUE(s2->save(umbmark_record()));
  auto w = s2->save(online_record());
  ASSERT_FALSE(w);
  EXPECT_EQ(w.error().code, Errc::kUnsupported);
  EXPECT_NE(w.error().message.find("does not fit"), std::string::npos);
  auto l2 = s2->load();
  ASSERT_TRUE(l2);
  EXPECT_EQ(l2->status, StoreStatus::kOk);
  EXPECT_EQ(l2->record->method, "umbmark");
}

}  // namespace
}  // namespace odo::calib
