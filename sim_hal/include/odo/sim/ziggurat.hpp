// ZigguratNormal: standard normal random numbers by Marsaglia & Tsang's ziggurat method (J. Stat.
// Software 5(8), 2000; 128 layers), drawn from a seeded 64-bit Mersenne twister. On 98.8 % of
// draws it costs one random word, a compare and a multiply, against a logarithm per pair for
// std::normal_distribution: the simulated gyro draws one per sample on the loop's path. The
// layer index and the value come from different bits of the word (Doornik 2005 showed that the
// original's shared bits correlate them). The words come from xoshiro256++ (Blackman & Vigna,
// "Scrambled linear pseudorandom number generators", ACM TOMS 2021; passes BigCrush and
// PractRand), seeded through SplitMix64 as its authors recommend: a dozen instructions a word
// against about 45 for std::mt19937_64. Deterministic for a seed on every platform.
#pragma once

#include <array>
#include <cstdint>

namespace odo::sim {

// Xoshiro256pp: xoshiro256++ 1.0, period 2^256 - 1, 64-bit words.
class Xoshiro256pp {
 public:
  // The four state words from SplitMix64 of the seed (never all zero).
  explicit Xoshiro256pp(std::uint64_t seed) noexcept;
  std::uint64_t operator()() noexcept {
    const std::uint64_t result = rotl(s_[0] + s_[3], 23) + s_[0];
    const std::uint64_t t = s_[1] << 17;
    s_[2] ^= s_[0];
    s_[3] ^= s_[1];
    s_[1] ^= s_[2];
    s_[0] ^= s_[3];
    s_[2] ^= t;
    s_[3] = rotl(s_[3], 45);
    return result;
  }

 private:
  static std::uint64_t rotl(std::uint64_t x, int k) noexcept { return (x << k) | (x >> (64 - k)); }
  std::array<std::uint64_t, 4> s_{};
};

class ZigguratNormal {
 public:
  explicit ZigguratNormal(std::uint64_t seed);
  // operator(): one N(0, 1) draw. Bits 7-31 of its first word play no part in it: they are kept
  // for spare_uniform().
  double operator()() noexcept {
    const std::uint64_t w = rng_();
    spare_ = static_cast<std::uint32_t>(w) >> 7;
    const auto hz = static_cast<std::int32_t>(static_cast<std::uint32_t>(w >> 32));
    const auto iz = static_cast<std::size_t>(w & 127u);
    const std::uint32_t mag =
        hz < 0 ? 0u - static_cast<std::uint32_t>(hz) : static_cast<std::uint32_t>(hz);
    if (mag < kn_[iz]) return hz * wn_[iz];
    return tail(hz, iz);
  }
  // uniform: one draw in [0, 1) from the same generator.
  double uniform() noexcept { return static_cast<double>(rng_() >> 11) * 0x1.0p-53; }
  // spare_uniform: a uniform draw in (0, 1) on 2^25 levels from the 25 bits of the last normal
  // draw's first word that the normal did not use (independent of it), at no generator cost.
  double spare_uniform() const noexcept { return (static_cast<double>(spare_) + 0.5) * 0x1.0p-25; }
  // spare_signed: 2 spare_uniform() - 1 in (-1, 1), bit for bit: every value is a multiple of
  // 2^-25 below 2 in magnitude, so each step of either form is exact.
  double spare_signed() const noexcept {
    return (static_cast<double>(spare_) - 0x1.ffffffp23) * 0x1.0p-24;
  }

 private:
  double tail(std::int32_t hz, std::size_t iz) noexcept;
  Xoshiro256pp rng_;
  std::uint32_t spare_ = 0;  // bits 7-31 of the last normal draw's first word
  std::array<std::uint32_t, 128> kn_{};
  std::array<double, 128> wn_{}, fn_{};
};

}  // namespace odo::sim
