// SimCanImu: a simulated CAN IMU on a SimCanPort: the simulated gyro (SimGyro, with its error
// terms) sampled at its output rate, each sample sent as one frame with the rate in a generic
// integer field (the layout an IMU's data sheet gives: id, byte offset, width, signedness, byte
// order, LSB and offset). The frames are packed here, independently of the firmware's decoder
// (drivers/can_gyro). Mounting: a chip mounted upside down sends the negated rate.
// Fault hook: the IMU stops sending (wire cut, reset) at a given robot time.
#pragma once

#include <cstdint>

#include "odo/hal/time.hpp"
#include "odo/sim/robot.hpp"
#include "odo/sim/sim_can_bus.hpp"
#include "odo/sim/sim_gyro.hpp"

namespace odo::sim {

struct SimCanImuOptions {
  std::uint32_t id = 0x120;  // arbitration id, 11-bit (extended false) or 29-bit
  bool extended = false;
  int byte_offset = 0;      // first byte of the rate field, 0..7
  int width_bits = 16;      // 16, 24 or 32
  bool is_signed = true;    // two's complement; false: unsigned (with `offset`)
  bool big_endian = false;  // byte order of the field
  double scale = 0.0;       // [rad/s per LSB], > 0
  double offset = 0.0;      // [rad/s]: rate = value * scale + offset
  int mounting = 1;         // +1 chip z up; -1 upside down (it sends the negated rate)
  TimeNs stop_after = -1;   // robot time [ns] from which no frame is sent; < 0 never
};

class SimCanImu {
 public:
  // gyro: the gyro model on the robot (owned). Everything runs on the robot's clock (frame
  // stamps too; EpochGyro maps a reader onto a real clock). The port has 64 transmit and 1024
  // receive slots. Not movable: callers hold its port.
  SimCanImu(SimGyro gyro, SimRobot& robot, const SimCanImuOptions& o);
  SimCanImu(const SimCanImu&) = delete;
  SimCanImu& operator=(const SimCanImu&) = delete;

  SimCanPort& port() noexcept { return port_; }
  // publish_until: one frame for every gyro sample available up to robot time `now` [ns], stamped
  // with its time; then the robot moves on to `now`.
  void publish_until(TimeNs now) noexcept;
  // frames: frames offered to the port so far.
  std::uint64_t frames() const noexcept { return frames_; }
  // pack: the field's value for `rate` [rad/s] (rounded, held to the field's range) in `f`'s data
  // (len 8); public for tests.
  void pack(double rate, CanFrame& f) const noexcept;

 private:
  SimCanPort port_;
  SimGyro gyro_;
  SimRobot& robot_;
  SimCanImuOptions opts_;
  TimeNs period_;    // the gyro's sample period [ns]
  TimeNs next_ = 0;  // robot time of the next read of the gyro [ns]
  std::uint64_t frames_ = 0;
};

}  // namespace odo::sim
