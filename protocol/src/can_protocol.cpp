#include "odo/protocol/can_protocol.hpp"

#include <cmath>
#include <limits>

#include "odo/odometry/pose.hpp"

namespace odo::protocol {
namespace {

// Little-endian (Intel) byte-aligned fields.
void put_le(CanFrame& f, int byte, int bytes, std::uint64_t raw) noexcept {
  for (int i = 0; i < bytes; ++i)
    f.data[static_cast<std::size_t>(byte + i)] = static_cast<std::uint8_t>(raw >> (8 * i));
}
std::uint64_t get_le(const CanFrame& f, int byte, int bytes) noexcept {
  std::uint64_t v = 0;
  for (int i = bytes - 1; i >= 0; --i) v = (v << 8) | f.data[static_cast<std::size_t>(byte + i)];
  return v;
}
std::int64_t get_le_signed(const CanFrame& f, int byte, int bytes) noexcept {
  const std::uint64_t v = get_le(f, byte, bytes);
  const int shift = 64 - 8 * bytes;
  return static_cast<std::int64_t>(v << shift) >> shift;  // sign-extend
}

// quantise: round(value / scale) clamped to [lo, hi]; NaN gives `nan_raw`.
std::int64_t quantise(double value, double scale, std::int64_t lo, std::int64_t hi,
                      std::int64_t nan_raw) noexcept {
  if (std::isnan(value)) return nan_raw;
  const double r = std::round(value / scale);
  if (r <= static_cast<double>(lo)) return lo;
  if (r >= static_cast<double>(hi)) return hi;
  return static_cast<std::int64_t>(r);
}

void start(std::uint32_t id, CanFrame& f) noexcept {
  f.id = id;
  f.extended = false;
  f.len = 8;
  f.data = {};
  f.stamp = 0;
}

constexpr std::int64_t kI32Min = std::numeric_limits<std::int32_t>::min();
constexpr std::int64_t kI32Max = std::numeric_limits<std::int32_t>::max();
constexpr std::int64_t kI24Min = -(1 << 23);
constexpr std::int64_t kI24Max = (1 << 23) - 1;

}  // namespace

bool valid_addressing(std::uint32_t base_id, int node) noexcept {
  return base_id % 16 == 0 && node >= 0 && node <= kMaxNodeId &&
         frame_id(base_id, node, Msg::kSetPose) + 7 <= 0x7FF;
}

bool split_id(std::uint32_t base_id, const CanFrame& f, int& node, Msg& m) noexcept {
  if (f.extended || f.id < base_id || f.id > 0x7FF) return false;
  const std::uint32_t rel = f.id - base_id;
  if (rel / 16 > static_cast<std::uint32_t>(kMaxNodeId)) return false;
  const std::uint32_t off = rel % 16;
  if (off > 5 && off != 8) return false;
  node = static_cast<int>(rel / 16);
  m = static_cast<Msg>(off);
  return true;
}

std::int64_t divisor_for(double loop_hz, double rate_hz) noexcept {
  if (rate_hz == 0.0) return 0;
  if (!(rate_hz > 0.0) || !(loop_hz > 0.0) || rate_hz > loop_hz) return -1;
  const double d = loop_hz / rate_hz;
  const double n = std::round(d);
  if (std::fabs(d - n) > 1e-9 * n) return -1;
  return static_cast<std::int64_t>(n);
}

std::int16_t theta_raw(double theta) noexcept {
  if (!std::isfinite(theta)) return 0;
  std::int64_t r = quantise(wrap_angle(theta), kThetaScale, -kThetaRawMax, kThetaRawMax, 0);
  if (r == -kThetaRawMax) r = kThetaRawMax;  // -pi after rounding is +pi
  return static_cast<std::int16_t>(r);
}

void encode_pose_x(std::uint32_t id, const PoseMsg& p, CanFrame& f) noexcept {
  start(id, f);
  put_le(f, 0, 4, static_cast<std::uint64_t>(quantise(p.x, kPosScale, kI32Min, kI32Max, 0)));
  f.data[7] = p.seq;
}

void encode_pose_y_theta(std::uint32_t id, const PoseMsg& p, CanFrame& f) noexcept {
  start(id, f);
  put_le(f, 0, 4, static_cast<std::uint64_t>(quantise(p.y, kPosScale, kI32Min, kI32Max, 0)));
  put_le(f, 4, 2, static_cast<std::uint16_t>(theta_raw(p.theta)));
  f.data[7] = p.seq;
}

void encode_velocity(std::uint32_t id, const VelocityMsg& v, CanFrame& f) noexcept {
  start(id, f);
  put_le(f, 0, 2, static_cast<std::uint64_t>(quantise(v.v, kVelScale, -32768, 32767, 0)));
  put_le(f, 2, 2, static_cast<std::uint64_t>(quantise(v.w, kOmegaScale, -32768, 32767, 0)));
  f.data[7] = v.seq;
}

void encode_uncertainty(std::uint32_t id, const UncertaintyMsg& u, CanFrame& f) noexcept {
  start(id, f);
  auto sigma = [](double s, double scale) {
    if (!std::isfinite(s)) return std::int64_t{65535};
    return quantise(s, scale, 0, 65535, 65535);
  };
  put_le(f, 0, 2, static_cast<std::uint64_t>(sigma(u.sigma_x, kSigmaPosScale)));
  put_le(f, 2, 2, static_cast<std::uint64_t>(sigma(u.sigma_y, kSigmaPosScale)));
  put_le(f, 4, 2, static_cast<std::uint64_t>(sigma(u.sigma_theta, kSigmaThetaScale)));
  f.data[6] = static_cast<std::uint8_t>(quantise(u.rho_xy, kRhoScale, -100, 100, 0));
  f.data[7] = u.seq;
}

void encode_status(std::uint32_t id, const StatusMsg& s, CanFrame& f) noexcept {
  start(id, f);
  f.data[0] = s.encoder_flags;
  f.data[1] = static_cast<std::uint8_t>((s.calibration_state & 0x3u) | (s.stopping ? 0x4u : 0u));
  f.data[2] = s.set_pose_ack;
  put_le(f, 3, 2, s.missed_deadlines > 65535u ? 65535u : s.missed_deadlines);
  put_le(f, 5, 3, static_cast<std::uint64_t>(quantise(std::floor(s.uptime), 1.0, 0, 0xFFFFFF, 0)));
}

void encode_timing(std::uint32_t id, const TimingMsg& t, CanFrame& f) noexcept {
  start(id, f);
  auto us = [](double s) {
    return static_cast<std::uint64_t>(quantise(s, kLatencyScale, 0, 65535, 65535));
  };
  put_le(f, 0, 2, us(t.wakeup_p99));
  put_le(f, 2, 2, us(t.wakeup_max));
  put_le(f, 4, 2, us(t.compute_max));
  put_le(f, 6, 2, t.tx_dropped > 65535u ? 65535u : t.tx_dropped);
}

void encode_set_pose(std::uint32_t id, const SetPoseCmd& c, CanFrame& f) noexcept {
  start(id, f);
  if (c.reset) {
    f.len = 0;
    return;
  }
  put_le(f, 0, 3, static_cast<std::uint64_t>(quantise(c.x, kSetPosScale, kI24Min, kI24Max, 0)));
  put_le(f, 3, 3, static_cast<std::uint64_t>(quantise(c.y, kSetPosScale, kI24Min, kI24Max, 0)));
  put_le(f, 6, 2, static_cast<std::uint16_t>(theta_raw(c.theta)));
}

bool decode_pose_x(const CanFrame& f, double& x, std::uint8_t& seq) noexcept {
  if (f.len != 8) return false;
  x = static_cast<double>(get_le_signed(f, 0, 4)) * kPosScale;
  seq = f.data[7];
  return true;
}

bool decode_pose_y_theta(const CanFrame& f, double& y, double& theta, std::uint8_t& seq) noexcept {
  if (f.len != 8) return false;
  y = static_cast<double>(get_le_signed(f, 0, 4)) * kPosScale;
  theta = static_cast<double>(get_le_signed(f, 4, 2)) * kThetaScale;
  seq = f.data[7];
  return true;
}

bool decode_velocity(const CanFrame& f, VelocityMsg& v) noexcept {
  if (f.len != 8) return false;
  v.v = static_cast<double>(get_le_signed(f, 0, 2)) * kVelScale;
  v.w = static_cast<double>(get_le_signed(f, 2, 2)) * kOmegaScale;
  v.seq = f.data[7];
  return true;
}

bool decode_uncertainty(const CanFrame& f, UncertaintyMsg& u) noexcept {
  if (f.len != 8) return false;
  u.sigma_x = static_cast<double>(get_le(f, 0, 2)) * kSigmaPosScale;
  u.sigma_y = static_cast<double>(get_le(f, 2, 2)) * kSigmaPosScale;
  u.sigma_theta = static_cast<double>(get_le(f, 4, 2)) * kSigmaThetaScale;
  u.rho_xy = static_cast<double>(get_le_signed(f, 6, 1)) * kRhoScale;
  u.seq = f.data[7];
  return true;
}

bool decode_status(const CanFrame& f, StatusMsg& s) noexcept {
  if (f.len != 8) return false;
  s.encoder_flags = f.data[0];
  s.calibration_state = f.data[1] & 0x3u;
  s.stopping = (f.data[1] & 0x4u) != 0;
  s.set_pose_ack = f.data[2];
  s.missed_deadlines = static_cast<std::uint32_t>(get_le(f, 3, 2));
  s.uptime = static_cast<double>(get_le(f, 5, 3));
  return true;
}

bool decode_timing(const CanFrame& f, TimingMsg& t) noexcept {
  if (f.len != 8) return false;
  t.wakeup_p99 = static_cast<double>(get_le(f, 0, 2)) * kLatencyScale;
  t.wakeup_max = static_cast<double>(get_le(f, 2, 2)) * kLatencyScale;
  t.compute_max = static_cast<double>(get_le(f, 4, 2)) * kLatencyScale;
  t.tx_dropped = static_cast<std::uint32_t>(get_le(f, 6, 2));
  return true;
}

bool decode_set_pose(const CanFrame& f, SetPoseCmd& c) noexcept {
  if (f.len == 0) {
    c = SetPoseCmd{true, 0.0, 0.0, 0.0};
    return true;
  }
  if (f.len != 8) return false;
  const std::int64_t th = get_le_signed(f, 6, 2);
  if (th < -kThetaRawMax || th > kThetaRawMax) return false;
  c.reset = false;
  c.x = static_cast<double>(get_le_signed(f, 0, 3)) * kSetPosScale;
  c.y = static_cast<double>(get_le_signed(f, 3, 3)) * kSetPosScale;
  c.theta = static_cast<double>(th) * kThetaScale;
  return true;
}

}  // namespace odo::protocol
