#include "odo/protocol/candump_log.hpp"

#include <cstdio>

#include "odo/protocol/signals.hpp"

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

namespace {

Error bad(const char* why) {
  return make_error(Errc::kParse, why);
}

// parse_stamp: "<seconds>.<6 digits>" (inside the parentheses) into out.sec, out.usec.
Status parse_stamp(std::string_view stamp, CandumpLine& out) {
  const std::size_t dot = stamp.find('.');
  if (dot == std::string_view::npos || !all_digits(stamp.substr(0, dot)) ||
      stamp.substr(dot + 1).size() != 6 || !all_digits(stamp.substr(dot + 1)) || dot > 12)
    return bad("time stamp must be seconds.microseconds (6 digits)");
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
  return Ok{};
}

// parse_iface: a Linux interface name: printable ASCII without blanks or '/'; anything else
// (a NUL byte, found by fuzz_candump) would not survive being printed back.
Status parse_iface(std::string_view name, CandumpLine& out) {
  for (char c : name) {
    if (c <= ' ' || c > '~' || c == '/')
      return bad("interface name must be printable ASCII without blanks or '/'");
  }
  out.iface = std::string(name);
  return Ok{};
}

// parse_id: 3 (standard) or 8 (extended) hex digits into f.id, f.extended.
Status parse_id(std::string_view id, CanFrame& f) {
  if (id.size() != 3 && id.size() != 8)
    return bad("CAN id must have 3 (standard) or 8 (extended) hex digits");
  std::uint32_t v = 0;
  for (char c : id) {
    const int h = hex_value(c);
    if (h < 0) return bad("CAN id is not hexadecimal");
    v = (v << 4) | static_cast<std::uint32_t>(h);
  }
  f.extended = id.size() == 8;
  if ((!f.extended && v > 0x7FF) || v > 0x1FFFFFFF) return bad("CAN id out of range");
  f.id = v;
  return Ok{};
}

// parse_data: 0..8 bytes as pairs of hex digits into f.data, f.len.
Status parse_data(std::string_view data, CanFrame& f) {
  if (!data.empty() && (data.front() == 'R' || data.front() == 'r' || data.front() == '#'))
    return bad("remote and CAN FD frames are not part of this protocol");
  if (data.size() % 2 != 0 || data.size() > 16)
    return bad("data must be 0..8 bytes as pairs of hex digits");
  for (std::size_t i = 0; i < data.size(); i += 2) {
    const int hi = hex_value(data[i]);
    const int lo = hex_value(data[i + 1]);
    if (hi < 0 || lo < 0) return bad("data is not hexadecimal");
    f.data[i / 2] = static_cast<std::uint8_t>(hi * 16 + lo);
  }
  f.len = static_cast<std::uint8_t>(data.size() / 2);
  return Ok{};
}

}  // namespace

Result<CandumpLine> parse_candump_line(std::string_view line) {
  if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
  CandumpLine out;
  if (line.empty() || line.front() != '(')
    return bad("expected '(seconds.microseconds)' at the start");
  const std::size_t close = line.find(')');
  if (close == std::string_view::npos) return bad("missing ')'");
  if (auto st = parse_stamp(line.substr(1, close - 1), out); !st) return std::move(st).error();
  std::string_view rest = line.substr(close + 1);
  if (rest.empty() || rest.front() != ' ') return bad("expected a space after the time stamp");
  rest.remove_prefix(1);
  const std::size_t sp = rest.find(' ');
  if (sp == 0 || sp == std::string_view::npos || sp > 15)
    return bad("expected an interface name (1..15 characters) and a frame");
  if (auto st = parse_iface(rest.substr(0, sp), out); !st) return std::move(st).error();
  const std::string_view fr = rest.substr(sp + 1);
  const std::size_t hash = fr.find('#');
  if (hash == std::string_view::npos) return bad("frame without '#'");
  if (auto st = parse_id(fr.substr(0, hash), out.frame); !st) return std::move(st).error();
  if (auto st = parse_data(fr.substr(hash + 1), out.frame); !st) return std::move(st).error();
  return out;
}

bool decode_protocol_frame(std::uint32_t base_id, const CanFrame& f, DecodedFrame& out) noexcept {
  if (!split_id(base_id, f, out.node, out.msg)) return false;
  const MessageSpec& m = message_spec(out.msg);
  out.message = m.name;
  out.n_fields = m.signals.size();
  if (out.msg == Msg::kSetPose) {
    SetPose c;
    if (!decode_set_pose(f, c)) return false;  // DLC 0 or 8, theta within its range
    if (f.len == 0) {
      out.message = "SetPose(reset)";
      for (std::size_t i = 0; i < out.n_fields; ++i) out.fields[i] = {m.signals[i]->name, 0.0};
      return true;
    }
  } else if (f.len != 8) {
    return false;
  }
  for (std::size_t i = 0; i < out.n_fields; ++i)
    out.fields[i] = {m.signals[i]->name, get_value(f, *m.signals[i])};
  return true;
}

std::size_t format_candump_line(char* buf, std::size_t size, std::int64_t wall_ns,
                                const char* iface, const CanFrame& f) noexcept {
  const long long sec = wall_ns / 1'000'000'000;
  const long long usec = (wall_ns % 1'000'000'000) / 1000;
  int n = f.extended ? std::snprintf(buf, size, "(%lld.%06lld) %s %08X#", sec, usec, iface,
                                     static_cast<unsigned>(f.id & 0x1FFFFFFFu))
                     : std::snprintf(buf, size, "(%lld.%06lld) %s %03X#", sec, usec, iface,
                                     static_cast<unsigned>(f.id & 0x7FFu));
  if (n < 0 || static_cast<std::size_t>(n) >= size) return 0;
  static constexpr char kHex[] = "0123456789ABCDEF";
  const std::size_t len = f.len > 8 ? 8 : f.len;
  if (static_cast<std::size_t>(n) + 2 * len + 2 > size) return 0;
  for (std::size_t i = 0; i < len; ++i) {
    buf[n++] = kHex[f.data[i] >> 4];
    buf[n++] = kHex[f.data[i] & 0xF];
  }
  buf[n++] = '\n';
  buf[n] = '\0';
  return static_cast<std::size_t>(n);
}

}  // namespace odo::protocol
