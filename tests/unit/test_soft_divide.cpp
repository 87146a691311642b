// The board's double division (board/soft_divide.hpp, wrapped in for libgcc's __aeabi_ddiv on
// the F405) against the host's hardware division: IEEE division is correctly rounded, so every
// quotient the fast path gives must have the host's bits, and the fast path must refuse what it
// does not handle (zero, subnormal, infinite, NaN operands; overflowing or subnormal quotients).
#include <gtest/gtest.h>

#include <bit>
#include <cstdint>
#include <limits>
#include <random>

#include "odo/board/soft_divide.hpp"

namespace {

using odo::board::divide_normal;

// fast: divide_normal of two doubles; whether it took them, and the quotient's bits.
struct Fast {
  bool taken = false;
  std::uint64_t bits = 0;
};
Fast fast(double a, double b) {
  Fast f;
  f.taken = divide_normal(std::bit_cast<std::uint64_t>(a), std::bit_cast<std::uint64_t>(b), f.bits);
  return f;
}

TEST(SoftDivide, HandDerivedQuotients) {
  // 1/3 = 0.0101...b: significand 1.0101...01|0101... rounds down (the next bit is 0), exponent
  // -2: 0x3FD5555555555555. 2/3 the same significand one binade up. 6/20 = 0.3 = the double
  // nearest 0.3, 0x3FD3333333333333 (1.0011...0011|0011... rounds down). 7/2 = 3.5 exactly.
  EXPECT_EQ(fast(1.0, 3.0).bits, 0x3FD5555555555555U);
  EXPECT_EQ(fast(2.0, 3.0).bits, 0x3FE5555555555555U);
  EXPECT_EQ(fast(6.0, 20.0).bits, 0x3FD3333333333333U);
  EXPECT_EQ(fast(-7.0, 2.0).bits, std::bit_cast<std::uint64_t>(-3.5));
  // 1 / (1 + 2^-52) = 1 - 2^-52 + 2^-104 - ...: below 1, between 1 - 2^-53 and 1 - 2^-52, nearer
  // 1 - 2^-52 (0x3FEFFFFFFFFFFFFE).
  EXPECT_EQ(fast(1.0, 0x1.0000000000001p0).bits, 0x3FEFFFFFFFFFFFFEU);
}

TEST(SoftDivide, RefusesWhatItDoesNotHandle) {
  const double inf = std::numeric_limits<double>::infinity();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double tiny = std::numeric_limits<double>::denorm_min();
  for (const auto& [a, b] :
       {std::pair{0.0, 1.0}, std::pair{1.0, 0.0}, std::pair{inf, 1.0}, std::pair{1.0, inf},
        std::pair{nan, 1.0}, std::pair{1.0, nan}, std::pair{tiny, 1.0}, std::pair{1.0, tiny},
        std::pair{1e300, 1e-300}, std::pair{1e-300, 1e300}})
    EXPECT_FALSE(fast(a, b).taken) << a << " / " << b;
}

TEST(SoftDivide, EqualsHardwareDivisionOnRandomOperands) {
  std::mt19937_64 g(36);
  constexpr std::uint64_t kFraction = (std::uint64_t{1} << 52) - 1;
  int taken = 0;
  constexpr int kN = 2000000;
  for (int i = 0; i < kN; ++i) {
    std::uint64_t x = g(), y = g();
    switch (i % 3) {
      case 1:  // both in [1, 2): every quotient is normal
        x = (x & kFraction) | (std::uint64_t{1023} << 52);
        y = (y & kFraction) | (std::uint64_t{1023} << 52);
        break;
      case 2:  // short significands (exact and near-exact quotients)
        x &= ~((std::uint64_t{1} << (g() % 53)) - 1);
        y &= ~((std::uint64_t{1} << (g() % 53)) - 1);
        break;
      default:  // any bits
        break;
    }
    const double a = std::bit_cast<double>(x), b = std::bit_cast<double>(y);
    const Fast f = fast(a, b);
    if (!f.taken) continue;
    ++taken;
    ASSERT_EQ(f.bits, std::bit_cast<std::uint64_t>(a / b)) << std::hexfloat << a << " / " << b;
  }
  EXPECT_GT(taken, kN / 2);  // the fast path is the common one
}

TEST(SoftDivide, TheTicksDivisionsTakeTheFastPath) {
  // The loop's divisions on the F405 (issue 36): heading series h^2/6, /20, /12 and the
  // wheelbase, here at a 1 mrad half-angle and a 0.337 m wheelbase.
  const double h2 = 1e-6;
  for (double b : {6.0, 20.0, 12.0, 0.337}) {
    const Fast f = fast(h2, b);
    EXPECT_TRUE(f.taken);
    EXPECT_EQ(f.bits, std::bit_cast<std::uint64_t>(h2 / b));
  }
}

}  // namespace
