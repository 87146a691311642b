// Linux IIO buffered scans (Documentation/ABI/testing/sysfs-bus-iio, "scan_elements"): the type
// string of a scan element, the layout of one scan in /dev/iio:deviceN, and the extraction of
// an element's value. Pure functions: no I/O, no allocation on the read path, no exceptions.
//
// Type string, as the kernel prints it (iio_show_fixed_type):
//   [be|le]:[s|u]<realbits>/<storagebits>>><shift>            e.g. "le:s16/16>>0", "be:s12/16>>4"
//   [be|le]:[s|u]<realbits>/<storagebits>X<repeat>>><shift>    e.g. "le:s16/16X3>>0"
// Capital S/U are accepted as the signed/unsigned flags too. The value is the storage word in
// the given byte order, shifted right by `shift`, masked to `realbits` and, when signed,
// sign-extended from bit realbits - 1.
//
// Scan layout (iio_compute_scan_bytes): the enabled elements in increasing index order, each
// aligned to its own size (storagebits/8, times repeat), and the whole scan padded to a
// multiple of the largest element.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>

#include "odo/hal/result.hpp"

namespace odo::drivers {

// IioScanType: one element's encoding.
struct IioScanType {
  bool big_endian = false;
  bool is_signed = true;
  int realbits = 16;     // significant bits, 1..64
  int storagebits = 16;  // 8, 16, 32 or 64, >= realbits + shift
  int shift = 0;         // right shift before masking, 0..storagebits - realbits
  int repeat = 1;        // elements stored back to back (1..255)
};

// parse_iio_scan_type: the type string (a trailing newline is allowed); the error quotes the
// text and says what was expected.
Result<IioScanType> parse_iio_scan_type(std::string_view text);

// element_bytes: the bytes one element occupies in a scan (storagebits/8 * repeat).
constexpr std::size_t element_bytes(const IioScanType& t) noexcept {
  return static_cast<std::size_t>(t.storagebits / 8) * static_cast<std::size_t>(t.repeat);
}

// iio_extract: the value of the (first repeat of the) element stored at `p`: `element_bytes`
// readable bytes.
std::int64_t iio_extract(const std::uint8_t* p, const IioScanType& t) noexcept;

// iio_raw_limits: the smallest and largest value the element can hold (saturation check).
void iio_raw_limits(const IioScanType& t, std::int64_t& lo, std::int64_t& hi) noexcept;

// IioScanElement: one enabled element for the layout computation.
struct IioScanElement {
  int index = 0;  // scan_elements/<name>_index
  IioScanType type;
};

// iio_scan_layout: byte offsets of the elements (given in increasing index order) within one
// scan, written to `offsets` (same size as `elements`); returns the scan size in bytes.
std::size_t iio_scan_layout(std::span<const IioScanElement> elements,
                            std::span<std::size_t> offsets) noexcept;

}  // namespace odo::drivers
