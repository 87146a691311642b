// A receive-only SocketCAN socket for the tools: `odomctl umbmark record --can IFACE` reads the
// daemon's pose broadcast from the bus itself. It lives here so that odomctl never sees a Linux
// type (drivers/ holds the socket; odomctl links firmware, not drivers).
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "odo/hal/can_bus.hpp"
#include "odo/hal/result.hpp"

namespace odo::fw {

// open_can_listener: a socket on the SocketCAN interface `interface` (can0, vcan0, ...) that
// receives only the standard 11-bit frames whose id is one of `ids`, non-blocking; it sends
// nothing. Errors name the interface and the failing call.
Result<std::unique_ptr<CanBus>> open_can_listener(const std::string& interface,
                                                  const std::vector<std::uint32_t>& ids);

}  // namespace odo::fw
