#include "odo/protocol/can_protocol.hpp"

#include <cmath>
#include <limits>

#include "odo/hal/angle.hpp"
#include "odo/protocol/signals.hpp"

namespace odo::protocol {
namespace {

// quantise: round(value / scale) clamped to [lo, hi]; NaN gives `nan_raw`.
std::int64_t quantise(double value, double scale, std::int64_t lo, std::int64_t hi,
                      std::int64_t nan_raw) noexcept {
  if (std::isnan(value)) return nan_raw;
  const double r = std::round(value / scale);
  if (r <= static_cast<double>(lo)) return lo;
  if (r >= static_cast<double>(hi)) return hi;
  return static_cast<std::int64_t>(r);
}

// put_value: `value` quantised to the signal (saturating at its range); NaN gives `nan_raw`.
void put_value(CanFrame& f, const Signal& s, double value, std::int64_t nan_raw = 0) noexcept {
  put_raw(f, s, quantise(value, s.scale, s.raw_min, s.raw_max, nan_raw));
}

// put_count: an unsigned counter, saturating at the signal's maximum.
void put_count(CanFrame& f, const Signal& s, std::uint64_t n) noexcept {
  const auto hi = static_cast<std::uint64_t>(s.raw_max);
  put_raw(f, s, static_cast<std::int64_t>(n > hi ? hi : n));
}

void start(std::uint32_t id, CanFrame& f) noexcept {
  f.id = id;
  f.extended = false;
  f.len = 8;
  f.data = {};
  f.stamp = 0;
}

}  // namespace

const MessageSpec& message_spec(Msg m) noexcept {
  for (const MessageSpec& s : kMessages)
    if (s.msg == m) return s;
  return kMessages[0];  // unreachable: every Msg is in the table
}

bool valid_addressing(std::uint32_t base_id, int node) noexcept {
  return base_id % 16 == 0 && node >= 0 && node <= kMaxNodeId &&
         frame_id(base_id, node, Msg::kSetPose) + 7 <= 0x7FF;
}

bool split_id(std::uint32_t base_id, const CanFrame& f, int& node, Msg& m) noexcept {
  if (f.extended || f.id < base_id || f.id > 0x7FF) return false;
  const std::uint32_t rel = f.id - base_id;
  if (rel / 16 > static_cast<std::uint32_t>(kMaxNodeId)) return false;
  const std::uint32_t off = rel % 16;
  // Ours are the offsets the message table lists; the others belong to no message.
  for (const MessageSpec& s : kMessages) {
    if (static_cast<std::uint32_t>(s.msg) != off) continue;
    node = static_cast<int>(rel / 16);
    m = s.msg;
    return true;
  }
  return false;
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
  put_value(f, sig::x, p.x);
  put_raw(f, sig::seq, p.seq);
}

void encode_pose_y_theta(std::uint32_t id, const PoseMsg& p, CanFrame& f) noexcept {
  start(id, f);
  put_value(f, sig::y, p.y);
  put_raw(f, sig::theta, theta_raw(p.theta));
  put_raw(f, sig::seq, p.seq);
}

void encode_velocity(std::uint32_t id, const VelocityMsg& v, CanFrame& f) noexcept {
  start(id, f);
  put_value(f, sig::v, v.v);
  put_value(f, sig::omega, v.omega);
  put_raw(f, sig::seq, v.seq);
}

void encode_uncertainty(std::uint32_t id, const UncertaintyMsg& u, CanFrame& f) noexcept {
  start(id, f);
  // Unknown (NaN) or infinite standard deviations are sent as the maximum.
  auto sigma = [&f](const Signal& s, double value) {
    put_value(f, s, std::isfinite(value) ? value : HUGE_VAL, s.raw_max);
  };
  sigma(sig::sigma_x, u.sigma_x);
  sigma(sig::sigma_y, u.sigma_y);
  sigma(sig::sigma_theta, u.sigma_theta);
  put_value(f, sig::rho_xy, u.rho_xy);
  put_raw(f, sig::seq, u.seq);
}

void encode_status(std::uint32_t id, const StatusMsg& s, CanFrame& f) noexcept {
  start(id, f);
  put_raw(f, sig::encoder_flags, s.encoder_flags);
  put_raw(f, sig::calibration_state, s.calibration_state & 0x3u);
  put_raw(f, sig::stopping, s.stopping ? 1 : 0);
  put_raw(f, sig::gyro_state, s.gyro_state & 0x3u);
  put_raw(f, sig::gyro_events, s.gyro_events & 0x7u);
  put_raw(f, sig::set_pose_ack, s.set_pose_ack);
  put_count(f, sig::missed_deadlines, s.missed_deadlines);
  put_value(f, sig::uptime, std::floor(s.uptime));
}

void encode_timing(std::uint32_t id, const TimingMsg& t, CanFrame& f) noexcept {
  start(id, f);
  const std::int64_t over = sig::wakeup_p99.raw_max;  // NaN: sent as the maximum
  put_value(f, sig::wakeup_p99, t.wakeup_p99, over);
  put_value(f, sig::wakeup_max, t.wakeup_max, over);
  put_value(f, sig::compute_max, t.compute_max, over);
  put_count(f, sig::tx_dropped, t.tx_dropped);
}

void encode_encoder_faults(std::uint32_t id, const EncoderCounters& c, CanFrame& f) noexcept {
  start(id, f);
  for (const auto& s : sig::kEncoderFaultFields) put_count(f, *s.signal, c.*s.field);
}

void encode_side_wheels(std::uint32_t id, const SideWheelsMsg& m, CanFrame& f) noexcept {
  start(id, f);
  for (const auto& s : sig::kSideWheelFlags)
    put_raw(f, *s.signal, (m.encoder_flags & s.flag) ? 1 : 0);
  put_count(f, sig::wheels_per_side, m.wheels_per_side);
  for (const auto& s : sig::kSideWheelCounters) put_count(f, *s.signal, m.counters.*s.field);
}

void encode_set_pose(std::uint32_t id, const SetPose& c, CanFrame& f) noexcept {
  start(id, f);
  put_value(f, sig::set_x, c.pose.x);
  put_value(f, sig::set_y, c.pose.y);
  put_raw(f, sig::set_theta, theta_raw(c.pose.theta));
}

void encode_set_pose_reset(std::uint32_t id, CanFrame& f) noexcept {
  start(id, f);
  f.len = 0;
}

bool decode_pose_x(const CanFrame& f, double& x, std::uint8_t& seq) noexcept {
  if (f.len != 8) return false;
  x = get_value(f, sig::x);
  seq = static_cast<std::uint8_t>(get_raw(f, sig::seq));
  return true;
}

bool decode_pose_y_theta(const CanFrame& f, double& y, double& theta, std::uint8_t& seq) noexcept {
  if (f.len != 8) return false;
  y = get_value(f, sig::y);
  theta = get_value(f, sig::theta);
  seq = static_cast<std::uint8_t>(get_raw(f, sig::seq));
  return true;
}

bool decode_velocity(const CanFrame& f, VelocityMsg& v) noexcept {
  if (f.len != 8) return false;
  v.v = get_value(f, sig::v);
  v.omega = get_value(f, sig::omega);
  v.seq = static_cast<std::uint8_t>(get_raw(f, sig::seq));
  return true;
}

bool decode_uncertainty(const CanFrame& f, UncertaintyMsg& u) noexcept {
  if (f.len != 8) return false;
  u.sigma_x = get_value(f, sig::sigma_x);
  u.sigma_y = get_value(f, sig::sigma_y);
  u.sigma_theta = get_value(f, sig::sigma_theta);
  u.rho_xy = get_value(f, sig::rho_xy);
  u.seq = static_cast<std::uint8_t>(get_raw(f, sig::seq));
  return true;
}

bool decode_status(const CanFrame& f, StatusMsg& s) noexcept {
  if (f.len != 8) return false;
  s.encoder_flags = static_cast<std::uint8_t>(get_raw(f, sig::encoder_flags));
  s.calibration_state = static_cast<std::uint8_t>(get_raw(f, sig::calibration_state));
  s.stopping = get_raw(f, sig::stopping) != 0;
  s.gyro_state = static_cast<std::uint8_t>(get_raw(f, sig::gyro_state));
  s.gyro_events = static_cast<std::uint8_t>(get_raw(f, sig::gyro_events));
  s.set_pose_ack = static_cast<std::uint8_t>(get_raw(f, sig::set_pose_ack));
  s.missed_deadlines = static_cast<std::uint32_t>(get_raw(f, sig::missed_deadlines));
  s.uptime = get_value(f, sig::uptime);
  return true;
}

bool decode_timing(const CanFrame& f, TimingMsg& t) noexcept {
  if (f.len != 8) return false;
  t.wakeup_p99 = get_value(f, sig::wakeup_p99);
  t.wakeup_max = get_value(f, sig::wakeup_max);
  t.compute_max = get_value(f, sig::compute_max);
  t.tx_dropped = static_cast<std::uint32_t>(get_raw(f, sig::tx_dropped));
  return true;
}

bool decode_encoder_faults(const CanFrame& f, EncoderCounters& c) noexcept {
  if (f.len != 8) return false;
  for (const auto& s : sig::kEncoderFaultFields)
    c.*s.field = static_cast<std::uint64_t>(get_raw(f, *s.signal));
  return true;
}

bool decode_side_wheels(const CanFrame& f, SideWheelsMsg& m) noexcept {
  if (f.len != 8) return false;
  m.encoder_flags = 0;
  for (const auto& s : sig::kSideWheelFlags)
    if (get_raw(f, *s.signal) != 0) m.encoder_flags |= s.flag;
  m.wheels_per_side = static_cast<std::uint8_t>(get_raw(f, sig::wheels_per_side));
  m.counters = EncoderCounters{};
  for (const auto& s : sig::kSideWheelCounters)
    m.counters.*s.field = static_cast<std::uint64_t>(get_raw(f, *s.signal));
  return true;
}

bool decode_set_pose(const CanFrame& f, SetPose& c) noexcept {
  if (f.len == 0) {
    c = SetPose{};
    return true;
  }
  if (f.len != 8) return false;
  const std::int64_t th = get_raw(f, sig::set_theta);
  if (th < sig::set_theta.raw_min || th > sig::set_theta.raw_max) return false;
  c.pose.x = get_value(f, sig::set_x);
  c.pose.y = get_value(f, sig::set_y);
  c.pose.theta = static_cast<double>(th) * sig::set_theta.scale;
  return true;
}

void encode_fix(std::uint32_t id_pose, std::uint32_t id_sigma, const FixMsg& m, CanFrame& pose,
                CanFrame& sigma) noexcept {
  start(id_pose, pose);
  put_value(pose, sig::fix_x, m.x);
  put_value(pose, sig::fix_y, m.y);
  put_raw(pose, sig::fix_seq, m.seq);
  start(id_sigma, sigma);
  const bool heading = m.sigma_theta > 0.0;
  put_raw(sigma, sig::fix_theta, heading ? theta_raw(m.theta) : 0);
  put_value(sigma, sig::fix_sigma_xy, m.sigma_xy, sig::fix_sigma_xy.raw_max);
  // A known heading keeps a sigma of at least one step: raw 0 would say "unknown".
  put_raw(sigma, sig::fix_sigma_theta,
          heading ? quantise(m.sigma_theta, kFixSigmaThetaScale, 1, sig::fix_sigma_theta.raw_max,
                             sig::fix_sigma_theta.raw_max)
                  : 0);
  put_value(sigma, sig::fix_age, m.age, sig::fix_age.raw_max);
  put_raw(sigma, sig::fix_seq, m.seq);
}

bool decode_fix_pose(const CanFrame& f, FixMsg& m) noexcept {
  if (f.len != 8) return false;
  m.x = get_value(f, sig::fix_x);
  m.y = get_value(f, sig::fix_y);
  m.seq = static_cast<std::uint8_t>(get_raw(f, sig::fix_seq));
  return true;
}

bool decode_fix_sigma(const CanFrame& f, FixMsg& m) noexcept {
  if (f.len != 8) return false;
  const std::int64_t th = get_raw(f, sig::fix_theta);
  if (th < sig::fix_theta.raw_min || th > sig::fix_theta.raw_max) return false;
  if (get_raw(f, sig::fix_sigma_xy) < sig::fix_sigma_xy.raw_min) return false;
  m.theta = static_cast<double>(th) * sig::fix_theta.scale;
  m.sigma_xy = get_value(f, sig::fix_sigma_xy);
  m.sigma_theta = get_value(f, sig::fix_sigma_theta);
  m.age = get_value(f, sig::fix_age);
  m.seq = static_cast<std::uint8_t>(get_raw(f, sig::fix_seq));
  return true;
}

}  // namespace odo::protocol
