#include "odo/drivers/iio_scan.hpp"

#include <string>

namespace odo::drivers {
namespace {

// Cursor over the type text; every take_* returns false when the text does not match.
struct Cursor {
  std::string_view s;
  bool take(std::string_view lit) noexcept {
    if (s.substr(0, lit.size()) != lit) return false;
    s.remove_prefix(lit.size());
    return true;
  }
  // take_uint: 1..3 decimal digits (no sign, no leading '+'), value <= max.
  bool take_uint(int& out, int max) noexcept {
    int v = 0;
    std::size_t n = 0;
    while (n < s.size() && n < 3 && s[n] >= '0' && s[n] <= '9') v = v * 10 + (s[n++] - '0');
    if (n == 0 || v > max || (n < s.size() && s[n] >= '0' && s[n] <= '9')) return false;
    s.remove_prefix(n);
    out = v;
    return true;
  }
};

// align: the kernel's ALIGN(x, a), a power-of-two mask; for the odd sizes of repeated elements
// (3 x 2 bytes) it is not a round-up, and the layout must still be the kernel's.
constexpr std::size_t align(std::size_t x, std::size_t a) noexcept {
  return (x + a - 1) & ~(a - 1);
}

Error bad_type(std::string_view text, const char* why) {
  return make_error(Errc::kParse, "IIO scan element type '" + std::string(text) + "': " + why +
                                      " (expected e.g. le:s16/16>>0 or be:u12/16X3>>4)");
}

}  // namespace

Result<IioScanType> parse_iio_scan_type(std::string_view text) {
  std::string_view body = text;
  if (!body.empty() && body.back() == '\n') body.remove_suffix(1);
  Cursor c{body};
  IioScanType t;
  if (c.take("be:")) {
    t.big_endian = true;
  } else if (!c.take("le:")) {
    return bad_type(text, "byte order must be be: or le:");
  }
  if (c.take("s") || c.take("S")) {
    t.is_signed = true;
  } else if (c.take("u") || c.take("U")) {
    t.is_signed = false;
  } else {
    return bad_type(text, "sign must be s or u");
  }
  if (!c.take_uint(t.realbits, 64) || t.realbits < 1) return bad_type(text, "realbits not 1..64");
  if (!c.take("/")) return bad_type(text, "missing '/' before storagebits");
  if (!c.take_uint(t.storagebits, 64) ||
      (t.storagebits != 8 && t.storagebits != 16 && t.storagebits != 32 && t.storagebits != 64))
    return bad_type(text, "storagebits not 8, 16, 32 or 64");
  if (c.take("X")) {
    if (!c.take_uint(t.repeat, 255) || t.repeat < 1) return bad_type(text, "repeat not 1..255");
  }
  if (!c.take(">>")) return bad_type(text, "missing '>>' before the shift");
  if (!c.take_uint(t.shift, 63)) return bad_type(text, "shift not 0..63");
  if (!c.s.empty()) return bad_type(text, "trailing characters");
  if (t.realbits + t.shift > t.storagebits)
    return bad_type(text, "realbits + shift exceed storagebits");
  return t;
}

std::int64_t iio_extract(const std::uint8_t* p, const IioScanType& t) noexcept {
  const int bytes = t.storagebits / 8;
  std::uint64_t w = 0;
  for (int i = 0; i < bytes; ++i) {
    const int at = t.big_endian ? i : bytes - 1 - i;
    w = (w << 8) | p[at];
  }
  w >>= t.shift;
  if (t.realbits < 64) {
    const std::uint64_t mask = (std::uint64_t{1} << t.realbits) - 1;
    w &= mask;
    // Sign extension by shifting the sign bit to the top and back (arithmetic shift).
    if (t.is_signed) {
      const int up = 64 - t.realbits;
      return static_cast<std::int64_t>(w << up) >> up;
    }
  }
  return static_cast<std::int64_t>(w);  // u64 above 2^63 wraps: no gyro has such a word
}

void iio_raw_limits(const IioScanType& t, std::int64_t& lo, std::int64_t& hi) noexcept {
  if (t.realbits >= 64) {
    lo = t.is_signed ? INT64_MIN : 0;
    hi = INT64_MAX;
    return;
  }
  if (t.is_signed) {
    hi = (std::int64_t{1} << (t.realbits - 1)) - 1;
    lo = -hi - 1;
  } else {
    lo = 0;
    hi = static_cast<std::int64_t>((std::uint64_t{1} << t.realbits) - 1);
  }
}

std::size_t iio_scan_layout(std::span<const IioScanElement> elements,
                            std::span<std::size_t> offsets) noexcept {
  std::size_t bytes = 0, largest = 1;
  for (std::size_t i = 0; i < elements.size() && i < offsets.size(); ++i) {
    const std::size_t len = element_bytes(elements[i].type);
    bytes = align(bytes, len);
    offsets[i] = bytes;
    bytes += len;
    if (len > largest) largest = len;
  }
  return align(bytes, largest);
}

}  // namespace odo::drivers
