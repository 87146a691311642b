#include "odo/ros2/mapping.hpp"

#include <cmath>
#include <string>

#include "odo/odometry/pose.hpp"

namespace odo::ros2 {

Quaternion quaternion_from_yaw(double theta) noexcept {
  // wrap_angle gives (-pi, pi], so the half angle is in (-pi/2, pi/2] and w = cos >= 0.
  const double h = 0.5 * wrap_angle(theta);
  return Quaternion{0.0, 0.0, std::sin(h), std::cos(h)};
}

double yaw_from_quaternion(const Quaternion& q) noexcept {
  // ZYX Euler yaw, written with w^2 + x^2 - y^2 - z^2 (= 1 - 2 (y^2 + z^2) for a unit q) so
  // that the scale of q cancels in atan2.
  return std::atan2(2.0 * (q.w * q.z + q.x * q.y), q.w * q.w + q.x * q.x - q.y * q.y - q.z * q.z);
}

namespace {

// Rows/columns of the 6x6 that our planar 3-vectors fill.
constexpr int kPoseIndex[3] = {kIx, kIy, kIyaw};  // (x, y, theta)
constexpr int kTwistIndex[2] = {kIx, kIyaw};      // (v, omega)

}  // namespace

Cov6 pose_covariance_6x6(const Cov3& c) noexcept {
  Cov6 out{};
  for (int r = 0; r < 3; ++r) {
    for (int col = 0; col < 3; ++col) out[kPoseIndex[r] * 6 + kPoseIndex[col]] = c[r * 3 + col];
  }
  for (int i : {kIz, kIroll, kIpitch}) out[i * 6 + i] = kUnobservedVariance;
  return out;
}

Cov6 twist_covariance_6x6(const Cov2& c) noexcept {
  Cov6 out{};
  for (int r = 0; r < 2; ++r) {
    for (int col = 0; col < 2; ++col) out[kTwistIndex[r] * 6 + kTwistIndex[col]] = c[r * 2 + col];
  }
  out[kIy * 6 + kIy] = kLateralSpeedVariance;
  for (int i : {kIz, kIroll, kIpitch}) out[i * 6 + i] = kUnobservedVariance;
  return out;
}

Result<RosTime> to_ros_time(TimeNs monotonic, TimeNs realtime_minus_monotonic) {
  const TimeNs t = monotonic + realtime_minus_monotonic;
  // Floor division: -1.7 s is {sec -2, nanosec 3e8} (builtin_interfaces/Time).
  TimeNs sec = t / kNsPerSecond;
  TimeNs ns = t % kNsPerSecond;
  if (ns < 0) {
    ns += kNsPerSecond;
    sec -= 1;
  }
  if (sec < INT32_MIN || sec > INT32_MAX) {
    return make_error(Errc::kInvalidArgument, "stamp " + std::to_string(sec) +
                                                  " s is outside builtin_interfaces/Time's int32 "
                                                  "seconds [-2147483648, 2147483647]");
  }
  return RosTime{static_cast<std::int32_t>(sec), static_cast<std::uint32_t>(ns)};
}

Result<OdometryFields> odometry_fields(const OdomSample& s, TimeNs realtime_minus_monotonic) {
  auto stamp = to_ros_time(s.stamp, realtime_minus_monotonic);
  if (!stamp) return std::move(stamp).error();
  OdometryFields f;
  f.stamp = *stamp;
  f.x = s.x;
  f.y = s.y;
  f.orientation = quaternion_from_yaw(s.theta);
  f.pose_cov = pose_covariance_6x6(s.pose_cov);
  // The twist is in the child frame (base_link): forward speed along x, turn rate about z.
  f.vx = s.v;
  f.wz = s.omega;
  f.twist_cov = twist_covariance_6x6(s.twist_cov);
  return f;
}

Result<PoseWithCovarianceFields> set_pose_from_fields(RosTime stamp, double x, double y,
                                                      const Quaternion& q, const Cov6& cov) {
  auto bad = [](const std::string& what) {
    return make_error(Errc::kInvalidArgument, "set_pose: " + what);
  };
  if (!std::isfinite(x) || !std::isfinite(y)) return bad("position x, y must be finite");
  const double n2 = q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w;
  if (!std::isfinite(n2) || n2 < 1e-12)
    return bad("orientation must be a finite non-zero quaternion");
  PoseWithCovarianceFields p;
  p.stamp = stamp;
  p.set_pose.pose = {x, y, yaw_from_quaternion(q)};
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) {
      const double v = cov[kPoseIndex[r] * 6 + kPoseIndex[c]];
      if (!std::isfinite(v)) return bad("covariance must be finite");
      p.cov[r * 3 + c] = v;
    }
  }
  for (int i = 0; i < 3; ++i) {
    if (p.cov[i * 3 + i] < 0.0) {
      return bad("covariance diagonal (x, y, yaw) = index " + std::to_string(kPoseIndex[i] * 7) +
                 " must be >= 0");
    }
  }
  return p;
}

}  // namespace odo::ros2
