// The calibration record encoding: CRC, byte layout, round trip, extension, range checks.
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstring>
#include <limits>
#include <string>

#include "odo/calibration/record.hpp"
#include "odo/hal/crc.hpp"

namespace odo::calib {
namespace {

CalibrationRecord full_record() {
  CalibrationRecord r;
  r.sequence = 0x0102030405060708ULL;
  r.c_l = 0.99925;
  r.c_r = 1.00075;
  r.wheelbase = 0.33702;
  r.wheel_diameter = 0.1503;
  r.e_s = 0.998;
  r.time = 1795000000;
  r.method = "umbmark";
  r.e_max_before = 0.232;
  r.e_max_after = 0.012;
  r.runs = 10;
  return r;
}

std::uint64_t le64(const std::vector<std::uint8_t>& b, std::size_t off) {
  std::uint64_t u = 0;
  for (int i = 0; i < 8; ++i) u |= static_cast<std::uint64_t>(b[off + i]) << (8 * i);
  return u;
}

TEST(CalibRecord, Crc32CheckValue) {
  // The catalogued check value of CRC-32/ISO-HDLC over the ASCII digits "123456789".
  const char* s = "123456789";
  EXPECT_EQ(crc32({reinterpret_cast<const std::uint8_t*>(s), 9}), 0xCBF43926U);
  EXPECT_EQ(crc32({}), 0x00000000U);
}

TEST(CalibRecord, ByteLayoutOfVersion1) {
  auto b = encode_record(full_record());
  ASSERT_TRUE(b) << b.error().message;
  ASSERT_EQ(b->size(), kRecordV1Bytes);
  EXPECT_EQ(std::string(b->begin(), b->begin() + 4), "ODCL");
  EXPECT_EQ((*b)[4], 1);  // version 1, little-endian u16
  EXPECT_EQ((*b)[5], 0);
  EXPECT_EQ((*b)[6], 108);  // length
  EXPECT_EQ(le64(*b, 8), 0x0102030405060708ULL);
  // flags: wheelbase, diameter, e_s, e_max before and after = bits 1..5 = 0x3E
  EXPECT_EQ((*b)[16], 0x3E);
  EXPECT_EQ((*b)[20], 10);  // runs
  EXPECT_EQ(le64(*b, 32), std::bit_cast<std::uint64_t>(0.99925));
  EXPECT_EQ(le64(*b, 48), std::bit_cast<std::uint64_t>(0.33702));
  EXPECT_EQ(std::string(reinterpret_cast<const char*>(b->data() + 88)), "umbmark");
  const std::uint32_t crc = crc32(std::span<const std::uint8_t>(b->data(), 104));
  EXPECT_EQ((*b)[104], crc & 0xFF);
  EXPECT_EQ((*b)[107], crc >> 24);
}

TEST(CalibRecord, RoundTripWithAndWithoutOptionalFields) {
  const CalibrationRecord r = full_record();
  auto b = encode_record(r);
  ASSERT_TRUE(b);
  auto d = decode_record(*b);
  ASSERT_TRUE(d) << d.error().message;
  EXPECT_EQ(*d, r);

  CalibrationRecord minimal;
  minimal.c_l = 0.995;
  minimal.sequence = 3;
  auto b2 = encode_record(minimal);
  ASSERT_TRUE(b2);
  auto d2 = decode_record(*b2);
  ASSERT_TRUE(d2);
  EXPECT_EQ(*d2, minimal);
  EXPECT_FALSE(d2->wheelbase.has_value());
  EXPECT_FALSE(d2->wheel_diameter.has_value());
}

TEST(CalibRecord, EverySingleBitFlipIsDetected) {
  // CRC-32 detects every single-bit error; the magic/version/length checks catch the header.
  auto b = encode_record(full_record());
  ASSERT_TRUE(b);
  for (std::size_t byte = 0; byte < b->size(); ++byte) {
    for (int bit = 0; bit < 8; ++bit) {
      auto c = *b;
      c[byte] ^= static_cast<std::uint8_t>(1U << bit);
      auto d = decode_record(c);
      ASSERT_FALSE(d) << "flip of byte " << byte << " bit " << bit << " went unnoticed";
      EXPECT_EQ(d.error().code, Errc::kCorrupt);
    }
  }
}

TEST(CalibRecord, LaterVersionWithExtraFieldsStillDecodes) {
  // A version-2 writer appends 16 bytes of new fields before the CRC and raises version and
  // length; this (version-1) reader keeps every version-1 field.
  auto b = encode_record(full_record());
  ASSERT_TRUE(b);
  std::vector<std::uint8_t> v2(b->begin(), b->begin() + 104);
  for (int i = 0; i < 16; ++i) v2.push_back(static_cast<std::uint8_t>(0xA0 + i));
  v2[4] = 2;
  v2[6] = 124;
  const std::uint32_t crc = crc32(v2);
  for (int i = 0; i < 4; ++i) v2.push_back(static_cast<std::uint8_t>(crc >> (8 * i)));
  v2.resize(256, 0xFF);  // the rest of the slot
  auto d = decode_record(v2);
  ASSERT_TRUE(d) << d.error().message;
  EXPECT_EQ(*d, full_record());
}

TEST(CalibRecord, DecodeNamesTheProblem) {
  std::vector<std::uint8_t> junk(128, 0x5A);
  auto d = decode_record(junk);
  ASSERT_FALSE(d);
  EXPECT_NE(d.error().message.find("magic"), std::string::npos);
  auto b = encode_record(full_record());
  ASSERT_TRUE(b);
  (*b)[40] ^= 1;
  d = decode_record(*b);
  ASSERT_FALSE(d);
  EXPECT_NE(d.error().message.find("CRC"), std::string::npos);
  (*b)[40] ^= 1;
  (*b)[6] = 200;  // length beyond the 108 bytes given
  d = decode_record(*b);
  ASSERT_FALSE(d);
  EXPECT_NE(d.error().message.find("length"), std::string::npos);
}

TEST(CalibRecord, RangeChecksNameFieldAndRange) {
  EXPECT_TRUE(validate_record(full_record()));
  auto r = full_record();
  r.c_l = 1.2;
  auto s = validate_record(r);
  ASSERT_FALSE(s);
  EXPECT_NE(s.error().message.find("c_l"), std::string::npos);
  EXPECT_NE(s.error().message.find("[0.9, 1.1]"), std::string::npos);
  r = full_record();
  r.c_r = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(validate_record(r));
  r = full_record();
  r.wheelbase = 0.0;
  s = validate_record(r);
  ASSERT_FALSE(s);
  EXPECT_NE(s.error().message.find("wheelbase"), std::string::npos);
  r = full_record();
  r.wheel_diameter = -0.15;
  EXPECT_FALSE(validate_record(r));
  r = full_record();
  r.e_s = 2.0;
  EXPECT_FALSE(validate_record(r));
  r = full_record();
  r.method = "a-very-long-method-name";
  EXPECT_FALSE(validate_record(r));
  EXPECT_FALSE(encode_record(r));
  r = full_record();
  r.wheelbase = std::numeric_limits<double>::infinity();
  EXPECT_FALSE(encode_record(r));
}

}  // namespace
}  // namespace odo::calib
