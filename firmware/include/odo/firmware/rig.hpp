// Rig: the wiring of one configuration: the clock, the encoder source and, in simulation, the
// simulated robot with its ground truth. The loop only ever sees the HAL interfaces.
#pragma once

#include <memory>
#include <optional>
#include <string>

#include "odo/firmware/config.hpp"
#include "odo/hal/clock.hpp"
#include "odo/hal/encoder.hpp"
#include "odo/hal/gyro.hpp"
#include "odo/hal/result.hpp"
#include "odo/loop/loop.hpp"
#include "odo/odometry/kinematics.hpp"

namespace odo::sim {
class TruthRecorder;
}

namespace odo::fw {

class Rig {
 public:
  ~Rig();
  Rig(Rig&&) noexcept;
  Rig& operator=(Rig&&) noexcept;

  // create: builds the backend named in cfg.encoder.backend. virtual_time: simulated clock that
  // runs as fast as the machine allows (simulated backends only).
  static Result<Rig> create(const Config& cfg, const Kinematics& k, bool virtual_time);

  Clock& clock() noexcept;
  EncoderSource& encoder() noexcept;
  // truth: the simulated robot's ground truth beside each tick, to register on the loop
  // (simulation only; null otherwise).
  sim::TruthRecorder* truth() noexcept;
  // gyro: the yaw-rate source of [gyro], null when backend = "none".
  YawRateSource* gyro() noexcept;
  // gyrodometry: the fusion parameters of [gyro] (tick and heading quantum set by the loop).
  GyrodometryParams gyrodometry() const;
  // describe: one line saying what is wired, for the start-up report.
  const std::string& describe() const noexcept;
  // scenario_duration: length of the simulated motion [s], 0 when not simulated.
  double scenario_duration() const noexcept;

 private:
  struct Impl;
  explicit Rig(std::unique_ptr<Impl> impl);
  // add_gyro: wires [gyro] on top of the encoders (rig.cpp).
  static Status add_gyro(const Config& cfg, Impl& impl, bool virtual_time);
  std::unique_ptr<Impl> impl_;
};

}  // namespace odo::fw
