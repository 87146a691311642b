// fuzz_require: the property checks of the fuzz targets. A violated property aborts, which
// libFuzzer reports as a finding (and saves the input) and which fails the corpus replay test.
#pragma once

#include <cstdio>
#include <cstdlib>
#include <string>

namespace odo::fuzz {

// require: abort with `what` (and `detail`) on stderr when `cond` is false.
inline void require(bool cond, const char* what, const std::string& detail = {}) {
  if (cond) return;
  std::fprintf(stderr, "fuzz property violated: %s %s\n", what, detail.c_str());
  std::abort();
}

// starts_with_location: `message` begins with "<source>:" followed by a line number >= 1.
inline bool starts_with_location(const std::string& message, const std::string& source) {
  if (message.compare(0, source.size() + 1, source + ":") != 0) return false;
  std::size_t i = source.size() + 1;
  if (i >= message.size() || message[i] < '1' || message[i] > '9') return false;
  while (i < message.size() && message[i] >= '0' && message[i] <= '9') ++i;
  return i < message.size() && message[i] == ':';
}

}  // namespace odo::fuzz
