// Pure mapping between diffodom's planar odometry and the fields of the ROS 2 messages
// nav_msgs/Odometry, tf2_msgs/TFMessage and geometry_msgs/PoseWithCovarianceStamped. No DDS
// types, no I/O, no clock reads: times and values are arguments (tests/unit/test_ros2_mapping).
#pragma once

#include <array>
#include <cstdint>

#include "odo/hal/result.hpp"
#include "odo/hal/time.hpp"
#include "odo/odometry/error_model.hpp"
#include "odo/odometry/pose.hpp"

namespace odo::ros2 {

using Cov6 = std::array<double, 36>;  // row-major 6x6, as in geometry_msgs

// One published state of the loop, as the DDS thread reads it from a snapshot.
struct OdomSample {
  TimeNs stamp = 0;    // encoder sample time on CLOCK_MONOTONIC [ns]
  double x = 0.0;      // [m] in the odometry frame
  double y = 0.0;      // [m]
  double theta = 0.0;  // [rad], cumulative (wrapped by the mapping)
  Cov3 pose_cov{};     // row-major 3x3 over (x, y, theta) [m^2, m rad, rad^2]
  double v = 0.0;      // forward speed of the base [m/s]
  double omega = 0.0;  // turn rate [rad/s], CCW positive
  Cov2 twist_cov{};    // row-major 2x2 over (v, omega)
};

// builtin_interfaces/Time: sec over all int32, nanosec in [0, 1e9).
struct RosTime {
  std::int32_t sec = 0;
  std::uint32_t nanosec = 0;
};

struct Quaternion {
  double x = 0.0, y = 0.0, z = 0.0, w = 1.0;
};

// The numeric fields of nav_msgs/Odometry (frame ids are fixed strings set at configure time);
// a TransformStamped odom -> base_link uses stamp, (x, y, 0) and orientation.
struct OdometryFields {
  RosTime stamp;
  double x = 0.0, y = 0.0, z = 0.0;     // pose.pose.position [m]
  Quaternion orientation;               // pose.pose.orientation
  Cov6 pose_cov{};                      // pose.covariance over (x, y, z, rotX, rotY, rotZ)
  double vx = 0.0, vy = 0.0, vz = 0.0;  // twist.twist.linear in the child frame [m/s]
  double wx = 0.0, wy = 0.0, wz = 0.0;  // twist.twist.angular [rad/s]
  Cov6 twist_cov{};                     // twist.covariance over (vx, vy, vz, wx, wy, wz)
};

// Indices of the 6-vector (x, y, z, rotX, rotY, rotZ) that the planar state fills.
inline constexpr int kIx = 0, kIy = 1, kIz = 2, kIroll = 3, kIpitch = 4, kIyaw = 5;

// Variance given to the dimensions wheel odometry does not observe: pose z, roll, pitch and
// twist vz, roll rate, pitch rate [m^2, rad^2, (m/s)^2, (rad/s)^2]. Large, not 0: the encoders
// carry no information on them (ramps, bumps, a tilting chassis), so a receiver that fuses them
// must not be pinned to 0 with false confidence; 1e6 is the value diff_drive_controller
// configurations commonly give these dimensions, and robot_localization (two_d_mode, or
// *_config false) ignores them anyway. Their cross terms are 0.
inline constexpr double kUnobservedVariance = 1e6;

// Variance of the lateral speed vy [(m/s)^2]. vy = 0 is the differential drive's non-holonomic
// constraint, an implicit measurement: robot_localization's docs say a differential drive "can
// safely fuse a 0 measurement for Y-dot with a small covariance value". Small but not 0 (1 cm/s
// standard deviation for wheel side slip), so that the 6x6 stays positive definite.
inline constexpr double kLateralSpeedVariance = 1e-4;

// quaternion_from_yaw: rotation by theta [rad] about z; theta is wrapped to (-pi, pi] first so
// that w >= 0 (one canonical sign for the same rotation).
Quaternion quaternion_from_yaw(double theta) noexcept;

// yaw_from_quaternion: heading [rad] in (-pi, pi] of the rotation q projected on the plane
// (q need not be normalised; the ZYX yaw).
double yaw_from_quaternion(const Quaternion& q) noexcept;

// pose_covariance_6x6: our 3x3 over (x, y, theta) placed at rows/columns (0, 1, 5); z, roll and
// pitch get kUnobservedVariance on the diagonal and no correlation.
Cov6 pose_covariance_6x6(const Cov3& c) noexcept;

// twist_covariance_6x6: our 2x2 over (v, omega) placed at (0, 5); vy gets kLateralSpeedVariance,
// vz, roll and pitch rates kUnobservedVariance.
Cov6 twist_covariance_6x6(const Cov2& c) noexcept;

// to_ros_time: monotonic sample time [ns] plus realtime_minus_monotonic [ns] (CLOCK_REALTIME -
// CLOCK_MONOTONIC read near the publish) as builtin_interfaces/Time; seconds floor toward minus
// infinity so nanosec is always in [0, 1e9). Error if the seconds leave int32 (year 2038).
Result<RosTime> to_ros_time(TimeNs monotonic, TimeNs realtime_minus_monotonic);

// odometry_fields: the whole mapping of one sample.
Result<OdometryFields> odometry_fields(const OdomSample& s, TimeNs realtime_minus_monotonic);

// The planar fields of a geometry_msgs/PoseWithCovarianceStamped received on set_pose: the
// request itself is odometry's SetPose (the one set-pose type; the loop takes it as is), beside
// what the message adds to it.
struct PoseWithCovarianceFields {
  RosTime stamp;     // header.stamp as received (system time)
  SetPose set_pose;  // x, y [m], theta [rad] in (-pi, pi]
  Cov3 cov{};        // row-major 3x3 over (x, y, theta), taken from rows/columns (0, 1, 5)
};

// set_pose_from_fields: a received PoseWithCovarianceStamped (position, orientation, 6x6) to its
// planar fields; error naming the field if a value is not finite, the quaternion is zero or the
// 3x3 diagonal is negative.
Result<PoseWithCovarianceFields> set_pose_from_fields(RosTime stamp, double x, double y,
                                                      const Quaternion& q, const Cov6& cov);

}  // namespace odo::ros2
