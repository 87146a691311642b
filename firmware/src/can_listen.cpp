#include "odo/firmware/can_listen.hpp"

#include "odo/drivers/socketcan_bus.hpp"

namespace odo::fw {

Result<std::unique_ptr<CanBus>> open_can_listener(const std::string& interface,
                                                  const std::vector<std::uint32_t>& ids) {
  drivers::SocketCanOptions o;
  o.interface = interface;
  // Kernel filters: on a busy bus the tool's socket queues only the frames it reads.
  for (const std::uint32_t id : ids) o.filters.push_back(drivers::CanFilter{id, 0x7FF, false});
  auto bus = drivers::SocketCanBus::open(o);
  if (!bus) return std::move(bus).error();
  return std::unique_ptr<CanBus>(std::move(bus).value());
}

}  // namespace odo::fw
