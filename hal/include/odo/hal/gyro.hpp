// YawRateSource: where the loop gets the robot's rate of turn about its z axis (a MEMS rate gyro
// through Linux IIO in drivers/, a simulated gyro with its error terms in sim_hal/).
#pragma once

#include <cstdint>

#include "odo/hal/choice.hpp"
#include "odo/hal/time.hpp"

namespace odo {

// Health flags of one gyro sample; several may be set at once. Any of them means the rate must
// not be used (the fusion falls back to odometry for that tick).
enum GyroFlag : std::uint32_t {
  kGyroOk = 0,
  kGyroStale = 1u << 0,      // no new device sample within the source's timeout
  kGyroSaturated = 1u << 1,  // a sample reached the end of the measuring range
  kGyroInvalid = 1u << 2,    // the rate is not a finite number (NaN, inf) or undecodable
  kGyroReadError = 1u << 3,  // the backend could not read the device this tick
  // No sample since start yet, and the first read was at most the source's timeout ago: the
  // device is still starting (an IIO buffer's first scan, a CAN IMU's first frame). Not usable,
  // but not a fault either; after the timeout it becomes kGyroStale.
  kGyroStarting = 1u << 4,
};

// The flags' names in odometryd's status line (README "Gyro"), in the order they are printed.
inline constexpr Choice<GyroFlag> kGyroFlagNames[] = {{kGyroStarting, "starting"},
                                                      {kGyroStale, "stale"},
                                                      {kGyroSaturated, "saturated"},
                                                      {kGyroInvalid, "invalid"},
                                                      {kGyroReadError, "read-error"}};

// Cumulative event counters of a gyro backend since start; they only grow.
struct GyroCounters {
  std::uint64_t samples = 0;       // device samples received
  std::uint64_t stale_events = 0;  // transitions into the stale state
  std::uint64_t saturated = 0;     // samples at the end of the range
  std::uint64_t invalid = 0;       // samples that were not finite or not decodable
  std::uint64_t read_errors = 0;   // reads the operating system refused
};

// One reading: the mean yaw rate over the device samples that arrived since the previous read.
struct GyroSample {
  double rate_z = 0.0;        // [rad/s] about the robot's z axis (CCW positive), mounting applied
  TimeNs stamp = 0;           // time of the newest device sample [ns, clock of the loop]
  std::uint32_t samples = 0;  // device samples averaged into rate_z (0: rate_z is the last one)
  std::uint32_t flags = 0;    // GyroFlag bits
  GyroCounters counters;
};

// GyroReadBook: the bookkeeping every gyro source does at the end of a read, shared by the IIO
// and CAN backends (drivers/) and the simulated gyro (sim_hal/) so that all flag and count alike.
// Start-up is one policy for all: until the first sample a read is kGyroStarting (rate 0, stamp
// 0) for stale_timeout from the first read, then kGyroStale with one stale event.
struct GyroReadBook {
  TimeNs stale_timeout = 0;  // no sample for longer than this: kGyroStale [ns]
  TimeNs last_stamp = 0;     // time of the newest sample; before the first, of the first read [ns]
  double last_rate = 0.0;    // newest mean rate [rad/s]
  bool stale = false;
  bool opened = false;  // close() has run
  GyroCounters counters;

  // close: s.samples samples of mean rate `mean` [rad/s] arrived in this read; fills rate_z (the
  // previous mean when none arrived), stamp, the stale flag (one stale event per transition into
  // the stale state) and the counters.
  void close(GyroSample& s, TimeNs now, double mean) noexcept {
    counters.samples += s.samples;
    if (counters.samples == 0) {  // rare: only while the device has never delivered
      close_waiting(s, now);
      return;
    }
    if (s.samples > 0) last_rate = mean;
    judge_stale(s, now);
    s.rate_z = last_rate;
    s.stamp = last_stamp;
    s.counters = counters;
  }

  // close_waiting: close() before the first sample: the device's wait counts from the first read
  // (not from a clock's zero or the source's construction, which may be long before the loop).
  void close_waiting(GyroSample& s, TimeNs now) noexcept {
    if (!opened) last_stamp = now;
    opened = true;
    if (!judge_stale(s, now)) s.flags |= kGyroStarting;
    s.rate_z = 0.0;  // no rate to repeat: never a made-up one that reads as valid
    s.stamp = 0;
    s.counters = counters;
  }

  // judge_stale: kGyroStale when nothing arrived for longer than stale_timeout since last_stamp,
  // one stale event per transition into it; true when stale.
  bool judge_stale(GyroSample& s, TimeNs now) noexcept {
    const bool now_stale = now - last_stamp > stale_timeout;
    if (now_stale) {
      s.flags |= kGyroStale;
      if (!stale) ++counters.stale_events;
    }
    stale = now_stale;
    return now_stale;
  }
};

class YawRateSource {
 public:
  virtual ~YawRateSource() = default;
  // read: everything the device delivered up to `now` [ns]; never blocks.
  virtual GyroSample read(TimeNs now) noexcept = 0;
  // read_into: the same, written into `out` (the loop reads into its fusion input, which a
  // returned sample would reach by a 64-byte copy); sources that can fill it in place override.
  virtual void read_into(TimeNs now, GyroSample& out) noexcept { out = read(now); }
  // full_scale: the measuring range, |rate| [rad/s] at which samples saturate.
  virtual double full_scale() const noexcept = 0;
};

}  // namespace odo
