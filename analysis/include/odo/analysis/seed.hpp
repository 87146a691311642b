// seed_of: independent, repeatable random seeds for the runs of a Monte Carlo.
#pragma once

#include <cstdint>

namespace odo::analysis {

// seed_of: a 64-bit seed for run i of a study seeded with `seed` (splitmix64 of seed and i).
inline std::uint64_t seed_of(std::uint64_t seed, std::uint64_t i) {
  std::uint64_t z = seed * 0x9E3779B97F4A7C15ULL + i + 0x632BE59BD9B4E019ULL;
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
  return z ^ (z >> 31);
}

}  // namespace odo::analysis
