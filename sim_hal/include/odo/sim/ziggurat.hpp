// ZigguratNormal: standard normal random numbers by Marsaglia & Tsang's ziggurat method (J. Stat.
// Software 5(8), 2000; 128 layers), drawn from a seeded 64-bit Mersenne twister. On 98.8 % of
// draws it costs one random word, a compare and a multiply, against a logarithm per pair for
// std::normal_distribution: the simulated gyro draws one per sample on the loop's path. The
// layer index and the value come from different bits of the word (Doornik 2005 showed that the
// original's shared bits correlate them). Deterministic for a seed on a given platform.
#pragma once

#include <array>
#include <cstdint>
#include <random>

namespace odo::sim {

class ZigguratNormal {
 public:
  explicit ZigguratNormal(std::uint64_t seed);
  // operator(): one N(0, 1) draw.
  double operator()() noexcept {
    const std::uint64_t w = rng_();
    const auto hz = static_cast<std::int32_t>(static_cast<std::uint32_t>(w >> 32));
    const auto iz = static_cast<std::size_t>(w & 127u);
    const std::uint32_t mag =
        hz < 0 ? 0u - static_cast<std::uint32_t>(hz) : static_cast<std::uint32_t>(hz);
    if (mag < kn_[iz]) return hz * wn_[iz];
    return tail(hz, iz);
  }
  // uniform: one draw in [0, 1) from the same generator.
  double uniform() noexcept { return static_cast<double>(rng_() >> 11) * 0x1.0p-53; }

 private:
  double tail(std::int32_t hz, std::size_t iz) noexcept;
  std::mt19937_64 rng_;
  std::array<std::uint32_t, 128> kn_{};
  std::array<double, 128> wn_{}, fn_{};
};

}  // namespace odo::sim
