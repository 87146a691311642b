// CanGyroSource: the yaw rate that a CAN IMU (or a motor controller's or a body controller's
// gyro) publishes cyclically, as a YawRateSource. Runs on any CanBus: SocketCanBus on a target
// (with a kernel receive filter for the one id), SimCanPort in tests and in the simulated rig.
//
// Frame: a generic layout, as the encoder backend's (CanCountLayout: id, 11/29-bit, byte offset,
// width 16, 24 or 32 bits, signed or unsigned, little or big endian); the field's value v [LSB]
// is the device's rate sign * (v * scale + offset) [rad/s], so that unsigned fields with a zero
// offset (J1939-style) are covered too. One frame is one device sample.
//
// read(now):
// - takes at most max_frames_per_read frames from the bus without blocking; the rate is the mean
//   of the samples taken (frames beyond stay queued for the next read);
// - a sample whose field holds the smallest or largest value of its width is at the end of the
//   device's range: kGyroSaturated (and counted); a frame with the id but too short a DLC is
//   kGyroInvalid (and counted); remote requests and other ids are ignored;
// - the stamp is the newest sample's receive time (SocketCanBus: when the loop read it, so the
//   [gyro] delay includes the transport); no sample for stale_timeout: kGyroStale; before the
//   first frame kGyroStarting, for stale_timeout from the first read (GyroReadBook).
#pragma once

#include <cstdint>

#include "odo/drivers/can_encoder.hpp"
#include "odo/hal/can_bus.hpp"
#include "odo/hal/gyro.hpp"
#include "odo/hal/result.hpp"
#include "odo/hal/time.hpp"

namespace odo::drivers {

struct CanGyroConfig {
  CanCountLayout field;               // where the rate sits; width 16, 24 or 32 bits
  double scale = 0.0;                 // [rad/s per LSB] of the field, > 0
  double offset = 0.0;                // [rad/s] added after scaling (0 for two's-complement rates)
  int sign = 1;                       // +1: the device's axis along the robot's z (up), -1: down
  TimeNs stale_timeout = 50'000'000;  // [ns] no sample for this long: stale
  int max_frames_per_read = 64;       // frames taken from the bus per read, 1..4096
};

// Per-source diagnostics beyond GyroCounters.
struct CanGyroStats {
  std::uint64_t frames = 0;        // frames taken from the bus
  std::uint64_t foreign = 0;       // frames of other ids (the kernel filter lets none pass)
  std::uint64_t remote = 0;        // remote requests with our id: ignored
  std::uint64_t capped_reads = 0;  // reads that stopped at max_frames_per_read
};

class CanGyroSource final : public YawRateSource {
 public:
  // create: validates the configuration (layout, width, scale, sign, ranges); `bus` must
  // outlive the source. The message names the field.
  static Result<CanGyroSource> create(CanBus& bus, const CanGyroConfig& cfg);

  GyroSample read(TimeNs now) noexcept override;
  // read_into: drains frames into `out`; see the header comment.
  void read_into(TimeNs now, GyroSample& out) noexcept override;
  // full_scale: the smaller |rate| of the field's two ends [rad/s].
  double full_scale() const noexcept override { return full_scale_; }

  const CanGyroStats& stats() const noexcept { return stats_; }

 private:
  CanGyroSource(CanBus& bus, const CanGyroConfig& cfg);
  double take(std::int64_t v, TimeNs stamp, GyroSample& s) noexcept;

  CanBus* bus_;
  CanGyroConfig cfg_;
  std::int64_t v_min_ = 0;  // the field's smallest and largest values [LSB]
  std::int64_t v_max_ = 0;
  double full_scale_ = 0.0;
  GyroReadBook book_;
  CanGyroStats stats_;
};

}  // namespace odo::drivers
