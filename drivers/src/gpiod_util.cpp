#include "gpiod_util.hpp"

#include <cerrno>
#include <cstring>
#include <ctime>

namespace odo::drivers {

Result<ChipHandle> open_chip(const std::string& descr) {
  gpiod_chip* c = gpiod_chip_open_lookup(descr.c_str());
  if (c == nullptr)
    return make_error(Errc::kNotFound,
                      "GPIO chip '" + descr + "' cannot be opened: " + std::strerror(errno));
  return ChipHandle(c);
}

gpiod_line* get_line(gpiod_chip* chip, unsigned offset) noexcept {
  if (offset >= gpiod_chip_num_lines(chip)) return nullptr;
  return gpiod_chip_get_line(chip, offset);
}

Error line_error(const std::string& chip, unsigned offset, const char* role) {
  const int e = errno;
  return make_error(Errc::kIo,
                    "GPIO chip '" + chip + "' line " + std::to_string(offset) + " (" + role +
                        ") cannot be requested: " + (e != 0 ? std::strerror(e) : "no such line"));
}

void sleep_ns(TimeNs ns) noexcept {
  if (ns <= 0) return;
  timespec ts{static_cast<time_t>(ns / kNsPerSecond), static_cast<long>(ns % kNsPerSecond)};
  while (nanosleep(&ts, &ts) != 0 && errno == EINTR) {
  }
}

}  // namespace odo::drivers
