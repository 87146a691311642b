// The CAN pose protocol (README "CAN protocol", protocol/odometry.dbc): classic CAN, 11-bit
// ids, 8-byte frames, Intel (little-endian) byte order. Frame id = base_id + 16 * node_id +
// message offset. Pure functions: no allocation, no exceptions; values outside a field's range
// saturate at its limits.
#pragma once

#include <cstdint>

#include "odo/hal/can_bus.hpp"
#include "odo/hal/encoder.hpp"
#include "odo/odometry/pose.hpp"

namespace odo::protocol {

constexpr std::uint32_t kDefaultBaseId = 0x400;
constexpr int kDefaultNodeId = 1;
constexpr int kMaxNodeId = 63;

// Message offsets within a node's block of 16 ids.
enum class Msg : std::uint8_t {
  kPoseX = 0,          // x, seq
  kPoseYTheta = 1,     // y, theta, seq
  kVelocity = 2,       // v, omega, seq
  kUncertainty = 3,    // sigma_x, sigma_y, sigma_theta, rho_xy, seq
  kStatus = 4,         // encoder flags, calibration state, stopping, set-pose ack, missed, uptime
  kTiming = 5,         // wake-up latency p99/max, compute max, transmit drops
  kEncoderFaults = 6,  // the encoder backend's eight fault counters (saturating at 255)
  kSideWheels = 7,     // several encoders per side: slip and dropped-wheel flags and counters
  kSetPose = 8,        // command to the node: set (DLC 8) or reset to zero (DLC 0)
  kFixPose = 9,        // absolute fix to the node, part 1: x, y, seq (self-calibration, issue 18)
  kFixSigma = 10,      // part 2: theta, sigma_xy, sigma_theta (0 = theta unknown), age, seq
};

// Scalings (physical = raw * scale).
constexpr double kPosScale = 1e-4;            // x, y [m] (int32: +-214.7 km)
constexpr double kThetaScale = 1e-4;          // theta [rad] (int16, raw -31415..31416)
constexpr std::int32_t kThetaRawMax = 31416;  // raw for +pi (pi rounded to the resolution)
constexpr double kVelScale = 1e-3;            // v [m/s] (int16: +-32.767 m/s)
constexpr double kOmegaScale = 1e-3;          // omega [rad/s] (int16: +-32.767 rad/s)
constexpr double kSigmaPosScale = 1e-4;       // sigma_x, sigma_y [m] (uint16, 65535 = >= 6.5535 m)
constexpr double kSigmaThetaScale = 1e-5;     // sigma_theta [rad] (uint16, 65535 = >= 0.65535 rad)
constexpr double kRhoScale = 0.01;            // rho_xy [-] (int8, -100..100)
constexpr double kLatencyScale = 1e-6;        // timing [s] (uint16 us, 65535 = >= 65.535 ms)
constexpr double kSetPosScale = 1e-3;         // set-pose x, y [m] (int24: +-8388.607 m)
constexpr double kFixSigmaXyScale = 1e-4;     // fix sigma_xy [m] (uint16, 0.1 mm .. 6.5535 m)
constexpr double kFixSigmaThetaScale = 1e-4;  // fix sigma_theta [rad] (uint12, <= 0.4095 rad)
constexpr double kFixAgeScale = 1e-3;         // fix age [s] (uint12 ms: up to 4.095 s late)

// frame_id: the 11-bit id of message m of node `node` (base_id a multiple of 16).
constexpr std::uint32_t frame_id(std::uint32_t base_id, int node, Msg m) noexcept {
  return base_id + 16u * static_cast<std::uint32_t>(node) + static_cast<std::uint32_t>(m);
}
// split_id: node and message of a standard id in our block; false for any other id.
bool split_id(std::uint32_t base_id, const CanFrame& f, int& node, Msg& m) noexcept;
// valid_addressing: base_id multiple of 16, node 0..63 and the node's block below 0x800.
bool valid_addressing(std::uint32_t base_id, int node) noexcept;

struct PoseMsg {
  double x = 0.0;      // [m]
  double y = 0.0;      // [m]
  double theta = 0.0;  // [rad], any value: wrapped to (-pi, pi] when encoded
  std::uint8_t seq = 0;
};
struct VelocityMsg {
  double v = 0.0;      // [m/s]
  double omega = 0.0;  // [rad/s], CCW positive
  std::uint8_t seq = 0;
};
struct UncertaintyMsg {
  double sigma_x = 0.0;      // [m]; NaN/inf = unknown (sent as the maximum)
  double sigma_y = 0.0;      // [m]
  double sigma_theta = 0.0;  // [rad]
  double rho_xy = 0.0;       // correlation of x and y, -1..1
  std::uint8_t seq = 0;
};
struct StatusMsg {
  std::uint8_t encoder_flags = 0;      // EncoderFlag bits 0..7
  std::uint8_t calibration_state = 0;  // 0 nominal, 1 calibrated, 2 corrupt store
  bool stopping = false;               // clean stop: the last status of this run
  std::uint8_t gyro_state = 0;         // 0 no gyro, 1 fusing, 2 learning the bias, 3 gyro fault
  std::uint8_t gyro_events = 0;        // bump/slip intervals detected, modulo 8
  std::uint8_t set_pose_ack = 0;       // set-pose commands applied, modulo 256
  std::uint32_t missed_deadlines = 0;  // saturates at 65535 on the wire
  double uptime = 0.0;                 // [s] loop time, 1 s resolution, saturates at 2^24-1
};
// SideWheelsMsg (issue 38): what several encoders per side add to Status's encoder flags (bits
// 0..7 only): the slip and dropped-wheel flags of the last sample and their event counters.
struct SideWheelsMsg {
  std::uint32_t encoder_flags = 0;   // EncoderFlag bits; only kSideWheelFlags' are carried
  std::uint8_t wheels_per_side = 2;  // 1..7 on the wire (the configuration caps it at 4)
  EncoderCounters counters;  // only slip_events and wheel_drops are carried, saturating at 65535
};
struct TimingMsg {
  double wakeup_p99 = 0.0;       // [s]
  double wakeup_max = 0.0;       // [s]
  double compute_max = 0.0;      // [s]
  std::uint32_t tx_dropped = 0;  // frames dropped by the transmit path; saturates at 65535
};

// FixMsg: an absolute pose fix for self-calibration, sent to the node as FixPose + FixSigma with
// the same seq. age: how long before the FixSigma frame's reception the fix was true, so a
// late fix is matched to the odometry of its moment.
struct FixMsg {
  double x = 0.0;            // [m], 1 mm resolution
  double y = 0.0;            // [m]
  double theta = 0.0;        // [rad], (-pi, pi]; ignored when sigma_theta == 0
  double sigma_xy = 0.0;     // [m] > 0
  double sigma_theta = 0.0;  // [rad] 0.1 mrad .. 0.4095 rad; 0 = heading unknown
  double age = 0.0;          // [s] 0..4.095
  std::uint8_t seq = 0;
};

// Encoders: fill f (id, len 8, data) as the frame with id `id`.
void encode_pose_x(std::uint32_t id, const PoseMsg& p, CanFrame& f) noexcept;
void encode_pose_y_theta(std::uint32_t id, const PoseMsg& p, CanFrame& f) noexcept;
void encode_velocity(std::uint32_t id, const VelocityMsg& v, CanFrame& f) noexcept;
void encode_uncertainty(std::uint32_t id, const UncertaintyMsg& u, CanFrame& f) noexcept;
void encode_status(std::uint32_t id, const StatusMsg& s, CanFrame& f) noexcept;
void encode_timing(std::uint32_t id, const TimingMsg& t, CanFrame& f) noexcept;
// encode_encoder_faults: the backend's counters, each saturating at 255.
void encode_encoder_faults(std::uint32_t id, const EncoderCounters& c, CanFrame& f) noexcept;
// encode_side_wheels: the SideWheels frame (flags, wheels per side, counters saturating).
void encode_side_wheels(std::uint32_t id, const SideWheelsMsg& m, CanFrame& f) noexcept;
// encode_set_pose: DLC 8 with x, y at 1 mm and theta (wrapped to (-pi, pi]) at 1e-4 rad.
void encode_set_pose(std::uint32_t id, const SetPose& c, CanFrame& f) noexcept;
// encode_set_pose_reset: the short form of SetPose{} (pose to (0, 0, 0)): DLC 0.
void encode_set_pose_reset(std::uint32_t id, CanFrame& f) noexcept;

// Decoders: false when the length is wrong (the id is the caller's business).
bool decode_pose_x(const CanFrame& f, double& x, std::uint8_t& seq) noexcept;
bool decode_pose_y_theta(const CanFrame& f, double& y, double& theta, std::uint8_t& seq) noexcept;
bool decode_velocity(const CanFrame& f, VelocityMsg& v) noexcept;
bool decode_uncertainty(const CanFrame& f, UncertaintyMsg& u) noexcept;
bool decode_status(const CanFrame& f, StatusMsg& s) noexcept;
bool decode_timing(const CanFrame& f, TimingMsg& t) noexcept;
// decode_encoder_faults: the counters as sent (255 = at least 255).
bool decode_encoder_faults(const CanFrame& f, EncoderCounters& c) noexcept;
// decode_side_wheels: the flags as EncoderFlag bits, the counters as sent (65535 = at least).
bool decode_side_wheels(const CanFrame& f, SideWheelsMsg& m) noexcept;
// encode_fix: the two frames of a fix (ids id_pose, id_sigma).
void encode_fix(std::uint32_t id_pose, std::uint32_t id_sigma, const FixMsg& m, CanFrame& pose,
                CanFrame& sigma) noexcept;
// decode_fix_pose / decode_fix_sigma: the halves of a fix (x, y, seq / the rest); false when
// the length is not 8, sigma_xy is 0 or theta is outside -31416..31416 raw.
bool decode_fix_pose(const CanFrame& f, FixMsg& m) noexcept;
bool decode_fix_sigma(const CanFrame& f, FixMsg& m) noexcept;
// decode_set_pose: DLC 0 = reset (SetPose{}); DLC 8 with |theta| <= pi (raw -31416..31416) =
// set; anything else (other lengths, theta out of range) is rejected with false.
bool decode_set_pose(const CanFrame& f, SetPose& c) noexcept;

// divisor_for: loop_hz / rate_hz [Hz / Hz] when that is a whole number >= 1 (to 1e-9), 0 for
// rate 0 (message off), -1 otherwise.
std::int64_t divisor_for(double loop_hz, double rate_hz) noexcept;

// theta_raw: the wire value of an angle: wrapped to (-pi, pi], rounded to 1e-4 rad, raw -31416
// (a rounded -pi) sent as +31416.
std::int16_t theta_raw(double theta) noexcept;

}  // namespace odo::protocol
