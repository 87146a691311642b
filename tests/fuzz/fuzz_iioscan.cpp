// Fuzz target: IIO scan-element type strings (odo::drivers::parse_iio_scan_type), the extraction
// of an element's value and the scan layout (drivers/iio_scan).
// Input: the type text up to the first NUL byte (or all of it); the bytes after the NUL are
// element data and, 4 at a time, further elements for the layout (byte 0: index, 1-3: which of
// a few types).
// Properties: no crash or UB (ASan, UBSan); a rejected text has a message quoting it; an accepted
// type is consistent (realbits + shift <= storagebits, storagebits 8/16/32/64, repeat >= 1) and
// its canonical print parses back to the same type; an extracted value lies within the type's
// limits; layout offsets are increasing, non-overlapping and the scan size covers them all.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <string>
#include <string_view>
#include <vector>

#include "fuzz_check.hpp"
#include "odo/drivers/iio_scan.hpp"

namespace {

using odo::drivers::IioScanType;

std::string canonical(const IioScanType& t) {
  char b[64];
  if (t.repeat > 1)
    std::snprintf(b, sizeof b, "%s:%c%d/%dX%d>>%d", t.big_endian ? "be" : "le",
                  t.is_signed ? 's' : 'u', t.realbits, t.storagebits, t.repeat, t.shift);
  else
    std::snprintf(b, sizeof b, "%s:%c%d/%d>>%d", t.big_endian ? "be" : "le",
                  t.is_signed ? 's' : 'u', t.realbits, t.storagebits, t.shift);
  return b;
}

bool same(const IioScanType& a, const IioScanType& b) {
  return a.big_endian == b.big_endian && a.is_signed == b.is_signed && a.realbits == b.realbits &&
         a.storagebits == b.storagebits && a.shift == b.shift && a.repeat == b.repeat;
}

void check_layout(const std::uint8_t* p, std::size_t n, const IioScanType& first) {
  using odo::fuzz::require;
  static const char* kTypes[] = {"le:s16/16>>0",   "le:s64/64>>0", "be:s24/32>>8",  "le:u8/8>>0",
                                 "le:s16/16X3>>0", "be:u12/16>>4", "le:s32/32X2>>0"};
  std::vector<odo::drivers::IioScanElement> els{{0, first}};
  for (std::size_t i = 0; i + 4 <= n && els.size() < 16; i += 4) {
    const auto t = odo::drivers::parse_iio_scan_type(kTypes[p[i + 1] % 7]);
    els.push_back({static_cast<int>(els.size()), *t});
  }
  std::vector<std::size_t> off(els.size());
  const std::size_t total = odo::drivers::iio_scan_layout(els, off);
  std::size_t end = 0;
  for (std::size_t i = 0; i < els.size(); ++i) {
    require(off[i] >= end, "elements overlap");
    end = off[i] + odo::drivers::element_bytes(els[i].type);
  }
  require(total >= end, "scan shorter than its elements");
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using odo::fuzz::require;
  std::size_t text_len = 0;
  while (text_len < size && data[text_len] != 0) ++text_len;
  const std::string text(reinterpret_cast<const char*>(data), text_len);
  const auto t = odo::drivers::parse_iio_scan_type(text);
  if (!t) {
    require(t.error().message.find("'" + text + "'") != std::string::npos,
            "error does not quote the text:", t.error().message);
    return 0;
  }
  require(t->realbits >= 1 && t->realbits + t->shift <= t->storagebits, "inconsistent bits");
  require(
      t->storagebits == 8 || t->storagebits == 16 || t->storagebits == 32 || t->storagebits == 64,
      "storagebits");
  require(t->repeat >= 1 && t->repeat <= 255, "repeat");
  const auto back = odo::drivers::parse_iio_scan_type(canonical(*t));
  require(back.ok() && same(*back, *t), "canonical print does not parse back:", canonical(*t));
  const std::uint8_t* rest = data + text_len + (text_len < size ? 1 : 0);
  const std::size_t left = size - static_cast<std::size_t>(rest - data);
  if (left >= odo::drivers::element_bytes(*t)) {
    const std::int64_t v = odo::drivers::iio_extract(rest, *t);
    std::int64_t lo = 0, hi = 0;
    odo::drivers::iio_raw_limits(*t, lo, hi);
    if (t->realbits < 64) require(v >= lo && v <= hi, "value outside the type's limits");
  }
  check_layout(rest, left, *t);
  return 0;
}
