#include "odo/board/text.hpp"

namespace odo::board {

Line& Line::add(const char* s) noexcept {
  while (*s != '\0') put(*s++);
  return *this;
}

Line& Line::num(std::int64_t v) noexcept {
  char d[24];
  int n = 0;
  // Negated as unsigned: INT64_MIN has no positive counterpart.
  std::uint64_t u = v < 0 ? ~static_cast<std::uint64_t>(v) + 1 : static_cast<std::uint64_t>(v);
  do {
    d[n++] = static_cast<char>('0' + u % 10);
    u /= 10;
  } while (u != 0);
  if (v < 0) put('-');
  while (n > 0) put(d[--n]);
  return *this;
}

}  // namespace odo::board
