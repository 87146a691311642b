// The configuration built into the firmware (a microcontroller reads no TOML): the same values
// as odometryd's defaults (firmware/config/odometryd.toml), which tests/mcu checks by comparing
// the firmware's broadcast with odometryd's.
#pragma once

#include <cstdint>

#include "odo/hal/side_wheels.hpp"
#include "odo/odometry/error_model.hpp"
#include "odo/odometry/kinematics.hpp"
#include "odo/protocol/can_protocol.hpp"

// The wheels per side this image is built for (board/CMakeLists.txt, ODO_BOARD_WHEELS_PER_SIDE):
// a build choice, since the encoder wiring and the serial record's version follow from it.
#ifndef ODO_BOARD_WHEELS_PER_SIDE
#define ODO_BOARD_WHEELS_PER_SIDE 1
#endif

namespace odo::board {

inline constexpr int kBoardWheelsPerSide = ODO_BOARD_WHEELS_PER_SIDE;
static_assert(kBoardWheelsPerSide >= 1 && kBoardWheelsPerSide <= kMaxWheelsPerSide);

struct BoardConfig {
  double rate_hz = 100.0;  // [Hz] loop rate ([loop] rate_hz)
  KinematicParams robot{0.15, 2048.0, 16.0, 0.34, 0.34, 1.0, 1.0};  // [robot]
  ErrorModelParams error_model{};                                   // [error_model]
  // [sim]: the LabMate driving one counter-clockwise 4 m square (0.2 m/s, 0.5 rad/s, 0.5 s).
  bool sim_labmate = true;
  double side = 4.0, speed = 0.2, turn_rate = 0.5, pause = 0.5;  // [m], [m/s], [rad/s], [s]
  int counter_bits = 32;
  // [encoder] wheels_per_side (1..4; several: version 2 serial records) and the combination's
  // other keys at their defaults (odometryd's [encoder] defaults).
  SideWheelsConfig wheels{kBoardWheelsPerSide};
  // [can]
  std::uint32_t base_id = protocol::kDefaultBaseId;
  int node_id = protocol::kDefaultNodeId;
  double pose_hz = 50.0;        // [Hz] PoseX + PoseYTheta
  double status_hz = 10.0;      // [Hz] Status
  std::uint32_t baud = 115200;  // USART1 (SLCAN) and USART2 (serial counts) [bit/s]
  double serial_hz = 100.0;  // [Hz] serial counts records on USART2 (0: off; 576/s max at 115200)
  std::uint32_t iwdg_timeout_ms = 100;  // watchdog: no tick for this long resets the chip
};

}  // namespace odo::board
