#include <gtest/gtest.h>

#include <cstdint>
#include <limits>

#include "odo/odometry/count_delta.hpp"

namespace odo {
namespace {

// Each case: a reading before and after the wrap, as the counter holds it (signed) and as a
// log may print it (unsigned). The expected delta is the short way round.
TEST(WrapDelta, SixteenBitsBothDirections) {
  // 0x7FFF -> 0x8000 is one count forward: signed 32767 -> -32768, unsigned 32767 -> 32768.
  EXPECT_EQ(wrap_delta(32767, -32768, 16), 1);
  EXPECT_EQ(wrap_delta(32767, 32768, 16), 1);
  // 0xFFFF -> 0x0000 is one count forward: signed -1 -> 0, unsigned 65535 -> 0.
  EXPECT_EQ(wrap_delta(65535, 0, 16), 1);
  EXPECT_EQ(wrap_delta(-1, 0, 16), 1);
  // And backwards: 0x0000 -> 0xFFFF is -1; 0x8000 -> 0x7FFF is -1.
  EXPECT_EQ(wrap_delta(0, 65535, 16), -1);
  EXPECT_EQ(wrap_delta(-32768, 32767, 16), -1);
  // 65530 -> 10 (unsigned) is 6 to the wrap plus 10 = +16.
  EXPECT_EQ(wrap_delta(65530, 10, 16), 16);
}

TEST(WrapDelta, TwentyFourBitsBothDirections) {
  // 2^23 - 1 = 8388607 -> -2^23 = -8388608 is +1.
  EXPECT_EQ(wrap_delta(8388607, -8388608, 24), 1);
  EXPECT_EQ(wrap_delta(-8388608, 8388607, 24), -1);
  // 8388600 -> -8388600: -16777200 mod 2^24 = 16, so +16 counts.
  EXPECT_EQ(wrap_delta(8388600, -8388600, 24), 16);
  EXPECT_EQ(wrap_delta(-8388600, 8388600, 24), -16);
  // Unsigned form: 16777215 (0xFFFFFF) -> 5 is +6.
  EXPECT_EQ(wrap_delta(16777215, 5, 24), 6);
  EXPECT_EQ(wrap_delta(5, 16777215, 24), -6);
}

TEST(WrapDelta, ThirtyTwoBitsBothDirections) {
  EXPECT_EQ(wrap_delta(2147483647, -2147483648LL, 32), 1);
  EXPECT_EQ(wrap_delta(-2147483648LL, 2147483647, 32), -1);
  EXPECT_EQ(wrap_delta(4294967295LL, 0, 32), 1);
  EXPECT_EQ(wrap_delta(0, 4294967295LL, 32), -1);
  // 4294967000 -> 1000 (unsigned): 296 to the wrap + 1000 = +1296.
  EXPECT_EQ(wrap_delta(4294967000LL, 1000, 32), 1296);
}

TEST(WrapDelta, SixtyFourBits) {
  constexpr auto kMax = std::numeric_limits<std::int64_t>::max();
  constexpr auto kMin = std::numeric_limits<std::int64_t>::min();
  EXPECT_EQ(wrap_delta(kMax, kMin, 64), 1);
  EXPECT_EQ(wrap_delta(kMin, kMax, 64), -1);
  EXPECT_EQ(wrap_delta(-5, 7, 64), 12);
}

TEST(WrapDelta, UsesOnlyLowBits) {
  // A reading with garbage above bit 23 is the same 24-bit reading.
  EXPECT_EQ(wrap_delta(0x12000010, 0x34000020, 24), 16);
}

TEST(NormaliseReading, AcceptsSignedAndUnsignedForms) {
  EXPECT_EQ(*normalise_reading(65535, 16), -1);
  EXPECT_EQ(*normalise_reading(-1, 16), -1);
  EXPECT_EQ(*normalise_reading(32768, 16), -32768);
  EXPECT_EQ(*normalise_reading(16777215, 24), -1);
  EXPECT_EQ(*normalise_reading(123, 24), 123);
}

TEST(NormaliseReading, RejectsOutOfRange) {
  auto r = normalise_reading(65536, 16);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().message.find("16-bit"), std::string::npos);
  EXPECT_FALSE(normalise_reading(-32769, 16).ok());
  EXPECT_FALSE(normalise_reading(1LL << 24, 24).ok());
}

TEST(NormaliseReading, SixtyThreeBitsWithoutOverflow) {
  // Regression (fuzz_replay): for 63 bits the unsigned range [0, 2^63 - 1] is every non-negative
  // int64 and the signed range starts at -2^62; computing 2 * 2^62 overflowed (UBSan).
  const std::int64_t kMax = INT64_MAX, kHalf = std::int64_t{1} << 62;
  EXPECT_EQ(*normalise_reading(kMax, 63), -1);  // 2^63 - 1 is all 63 bits set: -1 signed
  EXPECT_EQ(*normalise_reading(kHalf, 63), -kHalf);
  EXPECT_EQ(*normalise_reading(-kHalf, 63), -kHalf);
  EXPECT_EQ(*normalise_reading(4, 63), 4);
  auto r = normalise_reading(-kHalf - 1, 63);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().message.find("[-4611686018427387904, 9223372036854775807]"),
            std::string::npos)
      << r.error().message;
}

TEST(CounterBits, RangeIsSixteenToSixtyFour) {
  EXPECT_TRUE(check_counter_bits(16).ok());
  EXPECT_TRUE(check_counter_bits(64).ok());
  EXPECT_FALSE(check_counter_bits(15).ok());
  EXPECT_FALSE(check_counter_bits(65).ok());
}

}  // namespace
}  // namespace odo
