// Ground truth as a simulation attachment: the loop's snapshot carries only what the firmware
// knows; a simulated rig adds a TruthRecorder that publishes the robot's true pose beside each
// tick (for the status line, the final report and the tests), read from any thread.
#pragma once

#include <cstdint>

#include "odo/hal/gyro.hpp"
#include "odo/loop/loop.hpp"
#include "odo/loop/triple_buffer.hpp"
#include "odo/odometry/pose.hpp"
#include "odo/sim/robot.hpp"

namespace odo::sim {

// TruthSample: the true pose at a tick's sample time and the loop's pose of the same tick.
struct TruthSample {
  std::uint64_t tick = 0;
  Pose2 truth;  // cumulative heading
  Pose2 pose;   // the loop's pose of that tick
  // position_error: distance between the true and the estimated position [m].
  double position_error() const noexcept;
};

// TruthRecorder: a read-only TickObserver (loop thread; no allocation).
class TruthRecorder final : public loop::TickObserver {
 public:
  explicit TruthRecorder(const SimRobot& robot) : robot_(robot) {}
  void on_tick(const loop::LoopSnapshot& snap) noexcept override;
  // latest: the newest sample for another thread; false when none is new since the last call.
  bool latest(TruthSample& out) noexcept { return samples_.latest(out); }
  // newest: the newest sample (loop thread, or after the loop stopped).
  const TruthSample& newest() const noexcept { return samples_.newest(); }

 private:
  const SimRobot& robot_;
  loop::TripleBuffer<TruthSample> samples_;
};

// EpochEncoder: simulated encoders on a real clock, with the robot's time zero at the first
// read (the loop's reference reading), so the robot does not drive off during start-up while
// the odometry is not yet counting (seen as a 36 mm error after a 0.18 s start in the VM).
class EpochEncoder final : public EncoderSource {
 public:
  explicit EpochEncoder(EncoderSource& inner) : inner_(inner) {}
  EncoderSample read(TimeNs now) noexcept override;
  int counter_bits() const noexcept override { return inner_.counter_bits(); }

 private:
  EncoderSource& inner_;
  TimeNs epoch_ = 0;
  bool started_ = false;

 public:
  // epoch: the real time of the robot's time zero [ns] (0 until the first read).
  const TimeNs& epoch() const noexcept { return epoch_; }
};

// EpochGyro: a simulated gyro on the same real clock, with the robot's time zero at *epoch
// (an EpochEncoder's epoch, or a backend's fixed one); stamps are returned in real time.
class EpochGyro final : public YawRateSource {
 public:
  EpochGyro(YawRateSource& inner, const TimeNs& epoch) : inner_(inner), epoch_(epoch) {}
  GyroSample read(TimeNs now) noexcept override {
    GyroSample s = inner_.read(now - epoch_);
    s.stamp += epoch_;
    return s;
  }
  void read_into(TimeNs now, GyroSample& out) noexcept override {
    inner_.read_into(now - epoch_, out);
    out.stamp += epoch_;
  }
  double full_scale() const noexcept override { return inner_.full_scale(); }

 private:
  YawRateSource& inner_;
  const TimeNs& epoch_;
};

}  // namespace odo::sim
