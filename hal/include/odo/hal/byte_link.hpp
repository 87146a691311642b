// ByteLink: a byte stream to a peripheral (a serial line), read and written without blocking.
// A link that vanished (a USB device unplugged) reports it and may be opened again.
#pragma once

#include <cstdint>
#include <span>

#include "odo/hal/time.hpp"

namespace odo {

class ByteLink {
 public:
  virtual ~ByteLink() = default;
  // read: up to out.size() received bytes, without waiting; returns how many (0: none yet), or
  // -1 when the link is gone (closed until reopen() succeeds). `arrival`: when these bytes
  // arrived [ns, the loop's clock], for a link that stamps its input (bytes of one arrival per
  // call); others leave it as the caller set it.
  virtual int read(std::span<std::uint8_t> out, TimeNs& arrival) noexcept = 0;
  // write: queues all of `data` or none of it; false when it was not sent.
  virtual bool write(std::span<const std::uint8_t> data) noexcept = 0;
  // reopen: tries to open the link again (after read returned -1); true when it is open.
  virtual bool reopen() noexcept = 0;
};

}  // namespace odo
