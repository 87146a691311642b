// Number text for the core's messages without C++ streams: an ostringstream pulls the whole
// locale machinery of libstdc++ into a microcontroller image (88 KB of the STM32F405 build's
// flash, issue 36), while these give the same characters as `os << v` did: integers through
// std::to_chars (no locale), reals through the C library's "%.*g" (what ostream's num_put uses).
// std::to_chars for a double is not used: libstdc++'s links 120 KB of tables on picolibc.
#pragma once

#include <algorithm>
#include <charconv>
#include <concepts>
#include <cstdint>
#include <cstdio>
#include <string>

namespace odo {

// decimal_text: an integer in decimal, as std::to_string and `os << v` print it ("-12").
template <std::integral T>
std::string decimal_text(T v) {
  char b[24];  // 20 digits of 2^64 and a sign
  return std::string(b, std::to_chars(b, b + sizeof b, v).ptr);
}

// hex_text: an unsigned integer in lower-case hexadecimal without prefix or padding, as
// `os << std::hex << v` prints it ("deadbeef").
inline std::string hex_text(std::uint64_t v) {
  char b[16];
  return std::string(b, std::to_chars(b, b + sizeof b, v, 16).ptr);
}

// general_text: a real number as "%.*g" with `digits` significant digits; 6, the default, is
// what `os << v` prints at the stream's default precision ("0.123457", "1e+09", "nan").
inline std::string general_text(double v, int digits = 6) {
  char b[32];  // "-d.<16 digits>e-308" at the 17 digits that give any double back
  const int n = std::snprintf(b, sizeof b, "%.*g", digits, v);
  return std::string(b, n > 0 ? std::min(static_cast<std::size_t>(n), sizeof b - 1) : 0U);
}

}  // namespace odo
