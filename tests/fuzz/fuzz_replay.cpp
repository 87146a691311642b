// Fuzz target: the replay CSV reader (odo::analysis::replay_ticks on top of
// odo::analysis::CsvReader). Input: the first byte chooses the counter width (16..64 bits), the
// rest is the CSV text. Properties: never crashes, hangs or overflows (ASan, UBSan); a rejected
// file has a message "fuzz.csv:<line>: ..."; an accepted one has a finite pose and distance (and
// with fewer than two data rows, nothing to integrate, the start pose).
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <sstream>
#include <string>

#include "fuzz_check.hpp"
#include "odo/analysis/replay.hpp"
#include "odo/odometry/kinematics.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using odo::fuzz::require;
  if (size == 0) return 0;
  const int bits = 16 + data[0] % 49;
  std::istringstream in(std::string(reinterpret_cast<const char*>(data + 1), size - 1));
  // The reference robot: 0.15 m wheels, 2048 counts, 16:1 gear, 0.34 m wheelbase.
  static const odo::Kinematics k =
      odo::Kinematics::create(odo::KinematicParams{0.15, 2048, 16, 0.34, 0.34, 1.0, 1.0}).value();
  auto r = odo::analysis::replay_ticks(in, "fuzz.csv", k, bits);
  if (!r) {
    require(odo::fuzz::starts_with_location(r.error().message, "fuzz.csv"),
            "error message does not name file and line:", r.error().message);
    return 0;
  }
  if (r->samples < 2) {
    require(r->pose.x == 0.0 && r->pose.y == 0.0 && r->pose.theta == 0.0 && r->distance == 0.0,
            "moved without two data rows");
  }
  require(std::isfinite(r->pose.x) && std::isfinite(r->pose.y) && std::isfinite(r->pose.theta),
          "pose not finite");
  require(std::isfinite(r->distance) && r->distance >= 0.0, "distance not finite or negative");
  return 0;
}
