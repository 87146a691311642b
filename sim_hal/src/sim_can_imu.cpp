#include "odo/sim/sim_can_imu.hpp"

#include <algorithm>
#include <cmath>

namespace odo::sim {

SimCanImu::SimCanImu(SimGyro gyro, SimRobot& robot, const SimCanImuOptions& o)
    : port_(64, 1024),
      gyro_(std::move(gyro)),
      robot_(robot),
      opts_(o),
      period_(std::max<TimeNs>(1, from_seconds(1.0 / gyro_.model().odr))),
      next_(robot.time() + period_) {}

void SimCanImu::pack(double rate, CanFrame& f) const noexcept {
  const int w = opts_.width_bits;
  const double lo = opts_.is_signed ? -std::ldexp(1.0, w - 1) : 0.0;
  const double hi = opts_.is_signed ? std::ldexp(1.0, w - 1) - 1.0 : std::ldexp(1.0, w) - 1.0;
  // The chip rounds to its LSB and holds at the ends of its range (a saturated sample reads the
  // end value, which the decoder flags).
  const double v = std::clamp(std::nearbyint((rate - opts_.offset) / opts_.scale), lo, hi);
  const auto bits = static_cast<std::uint64_t>(static_cast<std::int64_t>(v));
  const auto n = static_cast<std::size_t>(w / 8);
  std::uint8_t* p = f.data.data() + opts_.byte_offset;
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t byte = opts_.big_endian ? n - 1 - i : i;  // byte i holds bits 8i..8i+7
    p[byte] = static_cast<std::uint8_t>(bits >> (8 * i));
  }
  f.len = 8;
}

void SimCanImu::publish_until(TimeNs now) noexcept {
  for (; next_ <= now; next_ += period_) {
    // The gyro moves the robot on to next_ when it is behind (the encoders usually did already).
    GyroSample s;
    gyro_.read_into(next_, s);
    // No new sample (the gyro's first `delay`), or a rate no integer field can carry (an
    // injected NaN): nothing is sent, as a chip without a new conversion sends nothing.
    if (s.samples == 0 || !std::isfinite(s.rate_z)) continue;
    if (opts_.stop_after >= 0 && next_ >= opts_.stop_after) continue;
    CanFrame f;
    f.id = opts_.id;
    f.extended = opts_.extended;
    f.stamp = next_;
    pack(opts_.mounting * s.rate_z, f);
    port_.inject(f);
    ++frames_;
  }
  if (now > robot_.time()) robot_.advance_to(now);
}

}  // namespace odo::sim
