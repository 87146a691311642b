// Wiring of [gyro] (issue 16): the yaw-rate source (a MEMS gyro through Linux IIO, or the
// simulated gyro on the simulated robot) and the gyrodometry parameters the loop fuses it with.
// Rig owns the returned object; the loop sees only its YawRateSource.
#pragma once

#include <memory>
#include <string>

#include "odo/firmware/config.hpp"
#include "odo/hal/gyro.hpp"
#include "odo/hal/result.hpp"
#include "odo/odometry/gyrodometry.hpp"

namespace odo::sim {
class SimRobot;
}

namespace odo::fw {

class GyroWiring {
 public:
  virtual ~GyroWiring() = default;
  virtual YawRateSource& gyro() noexcept = 0;
  // describe: one line for the start-up report.
  virtual const std::string& describe() const noexcept = 0;
};

// make_iio_gyro: [gyro] backend = "iio"; errors name the config file, the device and channel.
Result<std::unique_ptr<GyroWiring>> make_iio_gyro(const Config& cfg);

// make_sim_gyro: [gyro] backend = "sim": the model's gyro on `robot`; with `epoch` non-null the
// robot runs on the real clock with its time zero at *epoch [ns] (EpochGyro).
Result<std::unique_ptr<GyroWiring>> make_sim_gyro(const Config& cfg, sim::SimRobot& robot,
                                                  const TimeNs* epoch);

// make_can_socketcan_gyro: [gyro] backend = "can", [can_gyro] bus = "socketcan": a CAN IMU on a
// SocketCAN interface; errors name the config file and [can_gyro].
Result<std::unique_ptr<GyroWiring>> make_can_socketcan_gyro(const Config& cfg);

// make_can_sim_gyro: [gyro] backend = "can", [can_gyro] bus = "sim": the simulated CAN IMU (the
// [gyro] model on `robot`) read through the real decoder; `epoch` as for make_sim_gyro.
Result<std::unique_ptr<GyroWiring>> make_can_sim_gyro(const Config& cfg, sim::SimRobot& robot,
                                                      const TimeNs* epoch);

}  // namespace odo::fw
