// IEEE double division for a core without a double-precision unit (the Cortex-M4F's FPU is
// single precision): libgcc's __aeabi_ddiv produces the quotient a bit at a time, ~570
// instructions a division, five or six of them a tick (issue 36). This one divides 11 bits at
// a time with the core's 32-bit hardware divide for the estimate and an exact 64-bit remainder
// for the correction, ~160 instructions. IEEE division is correctly rounded, so any correct
// implementation gives the same bits: the result is libgcc's, and the host's.
#pragma once

#include <cstdint>

namespace odo::board {

// divide_normal: the bits of a / b (IEEE doubles given as bits), rounded to nearest-even, into
// `out` and true when a, b and the quotient are normal numbers; false (out untouched) for a
// zero, subnormal, infinite or NaN operand or a quotient that overflows or is subnormal, which
// the caller hands to a complete implementation.
inline bool divide_normal(std::uint64_t a, std::uint64_t b, std::uint64_t& out) noexcept {
  constexpr std::uint64_t kHidden = std::uint64_t{1} << 52;
  constexpr std::uint64_t kFraction = kHidden - 1;
  const auto ea = static_cast<unsigned>(a >> 52) & 0x7FFU;
  const auto eb = static_cast<unsigned>(b >> 52) & 0x7FFU;
  if (ea - 1U >= 0x7FEU || eb - 1U >= 0x7FEU) return false;  // 0: zero/subnormal, 0x7FF: inf/NaN
  std::uint64_t ma = (a & kFraction) | kHidden;
  const std::uint64_t mb = (b & kFraction) | kHidden;
  int e = static_cast<int>(ea) - static_cast<int>(eb) + 1023;
  if (ma < mb) {  // the quotient's significand in [1, 2)
    ma <<= 1;
    --e;
  }
  // Long division in base 2^11: q collects floor(ma 2^55 / mb), r < mb < 2^53 is the remainder
  // (so r << 11 fits 64 bits). The digit estimate from the top bits (mb >> 32 >= 2^20) is at
  // most 2 below and 1 above the digit; the remainder, exact in 64-bit two's complement (its
  // true value is within +-3 mb), corrects it.
  std::uint64_t q = 1;
  std::uint64_t r = ma - mb;
  const auto mt = static_cast<std::uint32_t>(mb >> 32);
  const auto smb = static_cast<std::int64_t>(mb);
  for (int i = 0; i < 5; ++i) {
    std::uint32_t d = static_cast<std::uint32_t>(r >> 21) / mt;
    auto rem = static_cast<std::int64_t>((r << 11) - static_cast<std::uint64_t>(d) * mb);
    for (; rem < 0; rem += smb) --d;
    for (; rem >= smb; rem -= smb) ++d;
    r = static_cast<std::uint64_t>(rem);
    q = (q << 11) | d;
  }
  // q in [2^55, 2^56): 53 bits of significand, then 3 guard bits; r != 0 is the sticky bit.
  const auto guard = static_cast<unsigned>(q & 7U);
  q >>= 3;
  if (guard > 4U || (guard == 4U && (r != 0 || (q & 1U) != 0))) ++q;
  if ((q >> 53) != 0) {  // rounded up to 2
    q >>= 1;
    ++e;
  }
  if (e < 1 || e > 2046) return false;
  out = ((a ^ b) & (std::uint64_t{1} << 63)) | (static_cast<std::uint64_t>(e) << 52) |
        (q & kFraction);
  return true;
}

}  // namespace odo::board
