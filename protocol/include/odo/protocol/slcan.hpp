// SLCAN: the Lawicel ASCII framing of CAN frames that CANable-class USB-CAN adapters speak and
// the Linux slcan driver turns into a SocketCAN interface: "tIIILDD..\r" (11-bit id),
// "TIIIIIIIILDD..\r" (29-bit id), "r"/"R" for remote frames; hex digits upper case. The
// microcontroller firmware sends the protocol's frames this way over a UART (issue 36).
// Pure, no allocation.
#pragma once

#include <cstddef>
#include <cstdint>

#include "odo/hal/can_bus.hpp"

namespace odo::protocol {

// kSlcanLineMax: the longest frame line, "T" + 8 id + 1 DLC + 16 data + "\r" [bytes].
inline constexpr std::size_t kSlcanLineMax = 27;

// encode_slcan: frame f as one SLCAN line (with its '\r') into out; its length [bytes].
std::size_t encode_slcan(const CanFrame& f, char (&out)[kSlcanLineMax]) noexcept;

// SlcanDecoder: byte-at-a-time reader of SLCAN lines. push() returns kFrame when a '\r' ended
// a valid frame line (frame() holds it), kCommand for other lines (adapter commands such as
// "O", "C", "S6" that slcand sends; command() holds the first character), kError for a
// malformed frame line or an overlong line, kNone while a line is incomplete.
class SlcanDecoder {
 public:
  enum class Event : std::uint8_t { kNone, kFrame, kCommand, kError };
  Event push(char c) noexcept;
  const CanFrame& frame() const noexcept { return frame_; }
  char command() const noexcept { return command_; }

 private:
  Event finish() noexcept;
  char line_[kSlcanLineMax] = {};
  std::size_t n_ = 0;
  bool overlong_ = false;
  CanFrame frame_;
  char command_ = 0;
};

}  // namespace odo::protocol
