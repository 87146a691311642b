#include "odo/protocol/candump_log.hpp"

#include <cctype>
#include <string>

namespace odo::protocol {
namespace {

int hex_value(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

bool all_digits(std::string_view s) {
  if (s.empty()) return false;
  for (char c : s)
    if (c < '0' || c > '9') return false;
  return true;
}

}  // namespace

Result<CandumpLine> parse_candump_line(std::string_view line) {
  if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
  CandumpLine out;
  if (line.empty() || line.front() != '(')
    return make_error(Errc::kParse, "expected '(seconds.microseconds)' at the start");
  const std::size_t close = line.find(')');
  if (close == std::string_view::npos) return make_error(Errc::kParse, "missing ')'");
  const std::string_view stamp = line.substr(1, close - 1);
  const std::size_t dot = stamp.find('.');
  if (dot == std::string_view::npos || !all_digits(stamp.substr(0, dot)) ||
      stamp.substr(dot + 1).size() != 6 || !all_digits(stamp.substr(dot + 1)) || dot > 12)
    return make_error(Errc::kParse, "time stamp must be seconds.microseconds (6 digits)");
  for (char c : stamp.substr(0, dot)) out.sec = out.sec * 10 + (c - '0');
  for (char c : stamp.substr(dot + 1)) out.usec = out.usec * 10 + (c - '0');
  // Callers turn the stamp into 64-bit nanoseconds (TimeNs): beyond 9223372035 s (the year
  // 2262) that overflows, so such a stamp is refused here (found by fuzz_candump).
  if (out.sec > kCandumpMaxSeconds) {
    return make_error(Errc::kParse, "time stamp " + std::to_string(out.sec) +
                                        " s is beyond the range of a 64-bit nanosecond clock "
                                        "(at most " +
                                        std::to_string(kCandumpMaxSeconds) + " s, year 2262)");
  }
  std::string_view rest = line.substr(close + 1);
  if (rest.empty() || rest.front() != ' ')
    return make_error(Errc::kParse, "expected a space after the time stamp");
  rest.remove_prefix(1);
  const std::size_t sp = rest.find(' ');
  if (sp == 0 || sp == std::string_view::npos || sp > 15)
    return make_error(Errc::kParse, "expected an interface name (1..15 characters) and a frame");
  // A Linux interface name is printable ASCII without blanks or '/'; anything else (a NUL byte,
  // found by fuzz_candump) would not survive being printed back.
  for (char c : rest.substr(0, sp)) {
    if (c <= ' ' || c > '~' || c == '/')
      return make_error(Errc::kParse,
                        "interface name must be printable ASCII without blanks or '/'");
  }
  out.iface = std::string(rest.substr(0, sp));
  const std::string_view fr = rest.substr(sp + 1);
  const std::size_t hash = fr.find('#');
  if (hash == std::string_view::npos) return make_error(Errc::kParse, "frame without '#'");
  const std::string_view id = fr.substr(0, hash);
  if (id.size() != 3 && id.size() != 8)
    return make_error(Errc::kParse, "CAN id must have 3 (standard) or 8 (extended) hex digits");
  std::uint32_t v = 0;
  for (char c : id) {
    const int h = hex_value(c);
    if (h < 0) return make_error(Errc::kParse, "CAN id is not hexadecimal");
    v = (v << 4) | static_cast<std::uint32_t>(h);
  }
  out.frame.extended = id.size() == 8;
  if ((!out.frame.extended && v > 0x7FF) || v > 0x1FFFFFFF)
    return make_error(Errc::kParse, "CAN id out of range");
  out.frame.id = v;
  const std::string_view data = fr.substr(hash + 1);
  if (!data.empty() && (data.front() == 'R' || data.front() == 'r' || data.front() == '#'))
    return make_error(Errc::kParse, "remote and CAN FD frames are not part of this protocol");
  if (data.size() % 2 != 0 || data.size() > 16)
    return make_error(Errc::kParse, "data must be 0..8 bytes as pairs of hex digits");
  for (std::size_t i = 0; i < data.size(); i += 2) {
    const int hi = hex_value(data[i]);
    const int lo = hex_value(data[i + 1]);
    if (hi < 0 || lo < 0) return make_error(Errc::kParse, "data is not hexadecimal");
    out.frame.data[i / 2] = static_cast<std::uint8_t>(hi * 16 + lo);
  }
  out.frame.len = static_cast<std::uint8_t>(data.size() / 2);
  return out;
}

bool decode_protocol_frame(std::uint32_t base_id, const CanFrame& f, DecodedFrame& out) noexcept {
  if (!split_id(base_id, f, out.node, out.msg)) return false;
  std::size_t n = 0;
  auto add = [&](const char* name, double v) { out.fields[n++] = DecodedField{name, v}; };
  switch (out.msg) {
    case Msg::kPoseX: {
      double x = 0;
      std::uint8_t seq = 0;
      if (!decode_pose_x(f, x, seq)) return false;
      out.message = "PoseX";
      add("x", x);
      add("seq", seq);
      break;
    }
    case Msg::kPoseYTheta: {
      double y = 0, th = 0;
      std::uint8_t seq = 0;
      if (!decode_pose_y_theta(f, y, th, seq)) return false;
      out.message = "PoseYTheta";
      add("y", y);
      add("theta", th);
      add("seq", seq);
      break;
    }
    case Msg::kVelocity: {
      VelocityMsg v;
      if (!decode_velocity(f, v)) return false;
      out.message = "Velocity";
      add("v", v.v);
      add("w", v.w);
      add("seq", v.seq);
      break;
    }
    case Msg::kUncertainty: {
      UncertaintyMsg u;
      if (!decode_uncertainty(f, u)) return false;
      out.message = "Uncertainty";
      add("sigma_x", u.sigma_x);
      add("sigma_y", u.sigma_y);
      add("sigma_theta", u.sigma_theta);
      add("rho_xy", u.rho_xy);
      add("seq", u.seq);
      break;
    }
    case Msg::kStatus: {
      StatusMsg s;
      if (!decode_status(f, s)) return false;
      out.message = "Status";
      add("encoder_flags", s.encoder_flags);
      add("calibration_state", s.calibration_state);
      add("stopping", s.stopping ? 1 : 0);
      add("set_pose_ack", s.set_pose_ack);
      add("missed_deadlines", s.missed_deadlines);
      add("uptime", s.uptime);
      break;
    }
    case Msg::kTiming: {
      TimingMsg t;
      if (!decode_timing(f, t)) return false;
      out.message = "Timing";
      add("wakeup_p99", t.wakeup_p99);
      add("wakeup_max", t.wakeup_max);
      add("compute_max", t.compute_max);
      add("tx_dropped", t.tx_dropped);
      break;
    }
    case Msg::kSetPose: {
      SetPoseCmd c;
      if (!decode_set_pose(f, c)) return false;
      out.message = c.reset ? "SetPose(reset)" : "SetPose";
      add("set_x", c.x);
      add("set_y", c.y);
      add("set_theta", c.theta);
      break;
    }
  }
  out.n_fields = n;
  return true;
}

}  // namespace odo::protocol
