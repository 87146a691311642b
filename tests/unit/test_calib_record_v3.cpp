// Calibration record version 3: the skid-steer ICR offset x_icr and its sigma (issue 38), and
// that version-1 and version-2 records and media keep working.
#include <gtest/gtest.h>

#include <bit>
#include <string>

#include "calib_record_test_util.hpp"
#include "odo/calibration/record.hpp"
#include "odo/calibration/store.hpp"
#include "odo/hal/crc.hpp"
#include "odo/odometry/kinematics.hpp"
#include "odo/sim/sim_nv_storage.hpp"

namespace odo::calib {
namespace {

using test::le;

// online_record: a self-calibration record of the skid-steer base (version 2).
CalibrationRecord online_record() {
  CalibrationRecord r = test::online_record();
  r.wheelbase = 0.5481;
  return r;
}

CalibrationRecord icr_record() {
  CalibrationRecord r = online_record();
  r.x_icr = 0.0309;
  r.sigma_x_icr = 0.0016;
  return r;
}

TEST(CalibRecordV3, ByteLayoutAndRoundTrip) {
  const CalibrationRecord r = icr_record();
  auto b = encode_record(r);
  ASSERT_TRUE(b) << b.error().message;
  ASSERT_EQ(b->size(), kRecordV3Bytes);
  EXPECT_EQ(le(*b, 4, 2), 3U);      // version
  EXPECT_EQ(le(*b, 6, 2), 164U);    // length
  EXPECT_EQ(le(*b, 16, 4), 0xC2U);  // flags: wheelbase (bit 1) + fit (bit 6) + x_icr (bit 7)
  EXPECT_EQ(le(*b, 144, 8), std::bit_cast<std::uint64_t>(0.0309));
  EXPECT_EQ(le(*b, 152, 8), std::bit_cast<std::uint64_t>(0.0016));
  EXPECT_EQ(le(*b, 160, 4), crc32(std::span<const std::uint8_t>(b->data(), 160)));
  auto d = decode_record(*b);
  ASSERT_TRUE(d) << d.error().message;
  EXPECT_EQ(*d, r);
  // The bytes below 144 are the version-2 encoding of the same record (only version, length
  // and the new flag bit differ): a version-2 reader reads its fit and runs without x_icr.
  auto b2 = encode_record(online_record());
  ASSERT_TRUE(b2);
  ASSERT_EQ(b2->size(), kRecordV2Bytes);
  for (std::size_t i = 8; i < 144; ++i)
    if (i != 16) {
      EXPECT_EQ((*b)[i], (*b2)[i]) << "byte " << i;
    }
  // x_icr without a fit (set by hand): version 3, the fit area zero and its flag clear.
  CalibrationRecord hand = online_record();
  hand.fit.reset();
  hand.x_icr = -0.02;
  auto bh = encode_record(hand);
  ASSERT_TRUE(bh);
  EXPECT_EQ(le(*bh, 16, 4), 0x82U);
  auto dh = decode_record(*bh);
  ASSERT_TRUE(dh) << dh.error().message;
  EXPECT_EQ(*dh, hand);
}

TEST(CalibRecordV3, OlderVersionsAreWrittenAndReadAsBefore) {
  // Without x_icr nothing changes: version 2 with a fit, version 1 without (the byte layouts
  // of CalibRecordV2).
  auto b2 = encode_record(online_record());
  ASSERT_TRUE(b2);
  EXPECT_EQ(le(*b2, 4, 2), 2U);
  CalibrationRecord v1 = online_record();
  v1.fit.reset();
  auto b1 = encode_record(v1);
  ASSERT_TRUE(b1);
  EXPECT_EQ(b1->size(), kRecordV1Bytes);
  auto d1 = decode_record(*b1);
  auto d2 = decode_record(*b2);
  ASSERT_TRUE(d1 && d2);
  EXPECT_FALSE(d1->x_icr);
  EXPECT_FALSE(d2->x_icr);
  EXPECT_EQ(*d2, online_record());
}

TEST(CalibRecordV3, EveryBitFlipDetectedAndFlagNeedsTheFields) {
  auto b = encode_record(icr_record());
  ASSERT_TRUE(b);
  test::expect_every_bit_flip_detected(*b);
  // The x_icr flag on a 148-byte version-2 record (CRC recomputed): corrupt, named.
  auto v2 = encode_record(online_record());
  ASSERT_TRUE(v2);
  test::expect_flag_needs_fields(*v2, 0x80, "x_icr flagged");
}

TEST(CalibRecordV3, ValidationAndApply) {
  CalibrationRecord r = icr_record();
  r.x_icr = 2.5;
  auto s = validate_record(r);
  ASSERT_FALSE(s);
  EXPECT_NE(s.error().message.find("x_icr"), std::string::npos) << s.error().message;
  r = online_record();
  r.sigma_x_icr = 0.001;  // a sigma of nothing would be lost on the medium
  ASSERT_FALSE(validate_record(r));
  KinematicParams nominal;
  nominal.wheel_diameter = 0.196;
  nominal.counts_per_rev = 2048;
  nominal.wheelbase_nominal = nominal.wheelbase = 0.5634;
  auto p = apply_record(nominal, icr_record());
  ASSERT_TRUE(p) << p.error().message;
  EXPECT_EQ(p->x_icr, 0.0309);
  EXPECT_EQ(p->wheelbase, 0.5481);
  auto q = apply_record(nominal, online_record());  // no x_icr: the config's stays
  ASSERT_TRUE(q);
  EXPECT_EQ(q->x_icr, 0.0);
}

TEST(CalibRecordV3, StoreRoundTripOverAnOldRecordAndAFailedSaveKeepsIt) {
  // 1 KiB EEPROM (slots of 512 bytes): a version-2 record first, then a version-3 one: the
  // newest loads with x_icr, the other slot still holds the version-2 record.
  sim::SimNvStorage big(sim::SimMedium::kEeprom, 1024, 0, 16);
  auto store = CalibrationStore::create(big);
  ASSERT_TRUE(store);
  ASSERT_TRUE(store->save(online_record()));
  ASSERT_TRUE(store->save(icr_record()));
  auto l = store->load();
  ASSERT_TRUE(l);
  ASSERT_TRUE(l->record);
  ASSERT_TRUE(l->record->x_icr);
  EXPECT_EQ(*l->record->x_icr, 0.0309);
  EXPECT_EQ(l->record->sigma_x_icr, 0.0016);
  auto old = test::other_slot(big, *l);
  ASSERT_TRUE(old);
  EXPECT_FALSE(old->x_icr);
  ASSERT_TRUE(old->fit);
  // A record the store refuses (x_icr out of range) writes nothing: the good one still loads.
  CalibrationRecord bad = icr_record();
  bad.x_icr = 3.0;
  ASSERT_FALSE(store->save(bad));
  auto again = store->load();
  ASSERT_TRUE(again && again->record);
  EXPECT_EQ(again->record->sequence, l->record->sequence);
  EXPECT_EQ(*again->record->x_icr, 0.0309);
}

}  // namespace
}  // namespace odo::calib
