// Private helpers for the libgpiod 1.6 drivers: chip lookup and readable errors.
#pragma once

#include <gpiod.h>

#include <memory>
#include <string>

#include "odo/hal/result.hpp"
#include "odo/hal/time.hpp"

namespace odo::drivers {

struct ChipCloser {
  void operator()(gpiod_chip* c) const noexcept { gpiod_chip_close(c); }
};
using ChipHandle = std::unique_ptr<gpiod_chip, ChipCloser>;

// open_chip: gpiod_chip_open_lookup (path, name, label or number), with an error naming it.
Result<ChipHandle> open_chip(const std::string& descr);
// get_line: the line at `offset`, or null.
gpiod_line* get_line(gpiod_chip* chip, unsigned offset) noexcept;
// line_error: "<chip> line <offset> (<role>): <strerror>".
Error line_error(const std::string& chip, unsigned offset, const char* role);
// sleep_ns: relative sleep [ns]; 0 returns at once.
void sleep_ns(TimeNs ns) noexcept;

}  // namespace odo::drivers
