// GpiodParallelBus: the HCTL-1100's multiplexed 8-bit bus (AD0..AD7, ALE, R/W, OE and one CS
// per chip) driven through GPIO lines with libgpiod 1.6. libgpiod types stay in the .cpp.
//
// Read cycle (all control lines given as logical levels; active-low pins are configured with
// the *_active_low options so "asserted" is always 1):
//   AD0..7 outputs = register address, R/W = read (1), CS asserted, ALE pulsed (address latched
//   on its falling edge), AD0..7 inputs, OE asserted, settle, sample AD0..7, OE and CS released.
// `settle` is the wait after every strobe [ns]: the chip needs none beyond the GPIO latency on a
// real board; the gpio-sim test (a software chip answering through sysfs) needs milliseconds.
#pragma once

#include <array>
#include <memory>
#include <string>
#include <vector>

#include "odo/hal/parallel_bus.hpp"
#include "odo/hal/result.hpp"
#include "odo/hal/time.hpp"

namespace odo::drivers {

// BusPhaseHook: told after each phase of a read cycle (after the settle wait). Diagnostics, and
// the gpio-sim test, where a software chip must answer through sysfs before the bus samples.
class BusPhaseHook {
 public:
  enum class Phase { kAddressLatched, kOutputEnabled, kReleased };
  virtual ~BusPhaseHook() = default;
  virtual void on_phase(int unit, Phase phase) noexcept = 0;
};

struct GpiodBusConfig {
  std::string chip;                // /dev/gpiochipN, gpiochipN, a chip label or a number
  std::array<unsigned, 8> ad{};    // line offsets of AD0..AD7
  unsigned ale = 0;                // address latch enable
  unsigned oe = 0;                 // output enable (chip drives AD when asserted)
  unsigned rw = 0;                 // read/write: 1 = read
  std::vector<unsigned> cs;        // one chip select per chip, unit i = cs[i]
  bool control_active_low = true;  // CS and OE are active-low pins (/CS, /OE)
  TimeNs settle = 0;               // [ns] wait after each strobe
  std::string consumer = "odometryd";
  BusPhaseHook* hook = nullptr;  // not owned; null: none
};

class GpiodParallelBus final : public ParallelBus {
 public:
  // open: requests the lines (control lines as outputs, released; AD lines as inputs). The
  // error names the chip and the line that could not be requested.
  static Result<std::unique_ptr<GpiodParallelBus>> open(const GpiodBusConfig& cfg);
  ~GpiodParallelBus() override;

  BusRead read_register(int unit, std::uint8_t reg) noexcept override;
  int units() const noexcept override;

 private:
  struct Impl;
  explicit GpiodParallelBus(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace odo::drivers
