// Fuzz target: the daemon's TOML config (odo::fw::parse_config).
// Properties: never crashes or leaks (ASan, UBSan); an accepted config has every field inside
// its documented range and builds valid kinematics and a valid loop rate; a rejected one has a
// message that starts with the file name.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "fuzz_check.hpp"
#include "odo/firmware/config.hpp"
#include "odo/odometry/kinematics.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using odo::fuzz::require;
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  auto c = odo::fw::parse_config(text, "fuzz.toml");
  if (!c) {
    const std::string& m = c.error().message;
    require(m.rfind("fuzz.toml", 0) == 0, "error message does not name the file:", m);
    return 0;
  }
  auto in = [](double v, double lo, double hi) { return std::isfinite(v) && v >= lo && v <= hi; };
  require(in(c->loop.rate_hz, 50.0, 2000.0), "loop.rate_hz out of range");
  require(in(c->loop.status_period, 0.0, 3600.0), "loop.status_period out of range");
  require(in(c->sim.side, 0.1, 100.0) && in(c->sim.speed, 0.01, 5.0) &&
              in(c->sim.turn_rate, 0.05, 10.0) && in(c->sim.pause, 0.0, 60.0),
          "sim motion parameter out of range");
  require(c->sim.counter_bits >= 16 && c->sim.counter_bits <= 64, "sim.counter_bits out of range");
  const std::string b(odo::fw::name_of(c->encoder.backend));
  require(b == "sim" || b == "hctl1100" || b == "gpio" || b == "can", "unknown backend", b);
  // [can_encoder]: an accepted generic layout fits a classic frame and its id length.
  const auto& e = c->can_encoder;
  const std::int64_t max_id = e.extended ? 0x1FFFFFFF : 0x7FF;
  require(e.width >= 16 && e.width <= 64 && e.width % 8 == 0, "can_encoder.width invalid");
  require(e.left_offset >= 0 && e.left_offset + e.width / 8 <= 8 && e.right_offset >= 0 &&
              e.right_offset + e.width / 8 <= 8,
          "can_encoder offset does not fit 8 bytes");
  require(e.left_id >= 0 && e.left_id <= max_id && e.right_id >= 0 && e.right_id <= max_id,
          "can_encoder id does not fit its length");
  require(
      in(e.timeout, 0.005, 10.0) && in(e.request_rate, 0.0, 1000.0) && in(e.max_speed, 0.01, 100.0),
      "can_encoder timing out of range");
  require(c->source == "fuzz.toml", "source not kept");
  auto k = odo::Kinematics::create(c->robot);
  require(k.ok(), "accepted robot section gives invalid kinematics:",
          k.ok() ? std::string() : k.error().message);
  require(std::isfinite(k->metres_per_count()) && k->metres_per_count() > 0.0,
          "metres per count not positive");
  return 0;
}
