#include "odo/protocol/slcan.hpp"

namespace odo::protocol {

namespace {

constexpr char kHex[] = "0123456789ABCDEF";

// hex_value: the value of one hex digit (either case), -1 for any other character.
int hex_value(char c) noexcept {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  return -1;
}

// parse_hex: `digits` hex digits at p into v; false when one is not a hex digit.
bool parse_hex(const char* p, std::size_t digits, std::uint32_t& v) noexcept {
  v = 0;
  for (std::size_t i = 0; i < digits; ++i) {
    const int d = hex_value(p[i]);
    if (d < 0) return false;
    v = (v << 4) | static_cast<std::uint32_t>(d);
  }
  return true;
}

}  // namespace

std::size_t encode_slcan(const CanFrame& f, char (&out)[kSlcanLineMax]) noexcept {
  const std::size_t id_digits = f.extended ? 8 : 3;
  const std::uint8_t len = f.len > 8 ? 8 : f.len;
  std::size_t n = 0;
  out[n++] = f.rtr ? (f.extended ? 'R' : 'r') : (f.extended ? 'T' : 't');
  for (std::size_t i = id_digits; i-- > 0;) out[n++] = kHex[(f.id >> (4 * i)) & 0xFu];
  out[n++] = kHex[len];
  if (!f.rtr) {
    for (std::size_t i = 0; i < len; ++i) {
      out[n++] = kHex[f.data[i] >> 4];
      out[n++] = kHex[f.data[i] & 0xFu];
    }
  }
  out[n++] = '\r';
  return n;
}

SlcanDecoder::Event SlcanDecoder::push(char c) noexcept {
  if (c == '\r') return finish();
  // '\n' and '\a' are not part of any line (a terminal's line ends, an adapter's error bell).
  if (c == '\n' || c == '\a') return Event::kNone;
  if (n_ < kSlcanLineMax)
    line_[n_++] = c;
  else
    overlong_ = true;
  return Event::kNone;
}

SlcanDecoder::Event SlcanDecoder::finish() noexcept {
  const std::size_t n = n_;
  const bool overlong = overlong_;
  n_ = 0;
  overlong_ = false;
  if (overlong) return Event::kError;
  if (n == 0) return Event::kNone;
  const char k = line_[0];
  if (k != 't' && k != 'T' && k != 'r' && k != 'R') {
    command_ = k;
    return Event::kCommand;
  }
  CanFrame f;
  f.extended = k == 'T' || k == 'R';
  f.rtr = k == 'r' || k == 'R';
  const std::size_t id_digits = f.extended ? 8 : 3;
  std::uint32_t v = 0;
  if (n < 1 + id_digits + 1 || !parse_hex(line_ + 1, id_digits, f.id)) return Event::kError;
  if (f.id > (f.extended ? 0x1FFFFFFFu : 0x7FFu)) return Event::kError;
  if (!parse_hex(line_ + 1 + id_digits, 1, v) || v > 8) return Event::kError;
  f.len = static_cast<std::uint8_t>(v);
  const std::size_t data_at = 2 + id_digits;
  if (n != data_at + (f.rtr ? 0 : 2u * f.len)) return Event::kError;
  for (std::size_t i = 0; !f.rtr && i < f.len; ++i) {
    if (!parse_hex(line_ + data_at + 2 * i, 2, v)) return Event::kError;
    f.data[i] = static_cast<std::uint8_t>(v);
  }
  frame_ = f;
  return Event::kFrame;
}

}  // namespace odo::protocol
