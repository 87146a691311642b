#include "odo/sim/ziggurat.hpp"

#include <cmath>

namespace odo::sim {
namespace {

// The 128-layer ziggurat's right end r and common layer area v (Marsaglia & Tsang, Sec. 4).
constexpr double kR = 3.442619855899;
constexpr double kV = 9.91256303526217e-3;
constexpr double kM1 = 2147483648.0;  // 2^31

}  // namespace

Xoshiro256pp::Xoshiro256pp(std::uint64_t seed) noexcept {
  // SplitMix64 (Steele, Lea & Flood 2014): consecutive outputs fill the state; its outputs are a
  // bijection of distinct counters, so the four words are never all zero.
  for (std::uint64_t& w : s_) {
    std::uint64_t z = (seed += 0x9e3779b97f4a7c15u);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9u;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebu;
    w = z ^ (z >> 31);
  }
}

ZigguratNormal::ZigguratNormal(std::uint64_t seed) : rng_(seed) {
  double dn = kR, tn = kR;
  const double q = kV / std::exp(-0.5 * dn * dn);
  kn_[0] = static_cast<std::uint32_t>((dn / q) * kM1);
  kn_[1] = 0;
  wn_[0] = q / kM1;
  wn_[127] = dn / kM1;
  fn_[0] = 1.0;
  fn_[127] = std::exp(-0.5 * dn * dn);
  for (int i = 126; i >= 1; --i) {
    dn = std::sqrt(-2.0 * std::log(kV / dn + std::exp(-0.5 * dn * dn)));
    kn_[static_cast<std::size_t>(i) + 1] = static_cast<std::uint32_t>((dn / tn) * kM1);
    tn = dn;
    fn_[static_cast<std::size_t>(i)] = std::exp(-0.5 * dn * dn);
    wn_[static_cast<std::size_t>(i)] = dn / kM1;
  }
}

double ZigguratNormal::tail(std::int32_t hz, std::size_t iz) noexcept {
  for (;;) {
    const double x = hz * wn_[iz];
    if (iz == 0) {  // the base layer's tail beyond r: Marsaglia's exponential rejection
      double t = 0.0, y = 0.0;
      do {
        t = -std::log(1.0 - uniform()) / kR;
        y = -std::log(1.0 - uniform());
      } while (y + y < t * t);
      return hz > 0 ? kR + t : -kR - t;
    }
    // A wedge: accept under the density.
    if (fn_[iz] + uniform() * (fn_[iz - 1] - fn_[iz]) < std::exp(-0.5 * x * x)) return x;
    const std::uint64_t w = rng_();
    hz = static_cast<std::int32_t>(static_cast<std::uint32_t>(w >> 32));
    iz = static_cast<std::size_t>(w & 127u);
    const std::uint32_t mag =
        hz < 0 ? 0u - static_cast<std::uint32_t>(hz) : static_cast<std::uint32_t>(hz);
    if (mag < kn_[iz]) return hz * wn_[iz];
  }
}

}  // namespace odo::sim
