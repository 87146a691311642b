// frame: a received CAN frame written byte by byte, for the decoder tests (independent of the
// code under test).
#pragma once

#include <cstddef>
#include <cstdint>
#include <initializer_list>

#include "odo/hal/can_bus.hpp"

namespace odo::test {

// frame: id, data bytes (len = their number, at most 8), receive stamp [ns], 29-bit id.
inline CanFrame frame(std::uint32_t id, std::initializer_list<std::uint8_t> bytes, TimeNs stamp = 0,
                      bool extended = false) {
  CanFrame f;
  f.id = id;
  f.extended = extended;
  f.len = static_cast<std::uint8_t>(bytes.size());
  std::size_t i = 0;
  for (std::uint8_t b : bytes) f.data[i++] = b;
  f.stamp = stamp;
  return f;
}

}  // namespace odo::test
