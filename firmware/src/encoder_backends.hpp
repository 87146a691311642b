// Wiring of the hardware encoder backends of issue 5: the HCTL-1100 pair (over the libgpiod bus
// or over the register model that follows the simulated robot) and GPIO quadrature. Rig owns
// the returned object; the loop sees only its EncoderSource.
#pragma once

#include <memory>
#include <string>

#include "odo/drivers/can_encoder.hpp"
#include "odo/firmware/config.hpp"
#include "odo/hal/clock.hpp"
#include "odo/hal/encoder.hpp"
#include "odo/hal/result.hpp"
#include "odo/odometry/kinematics.hpp"
#include "odo/protocol/serial_counts_source.hpp"

namespace odo::sim {
class SimRobot;
}

namespace odo::fw {

class EncoderBackend {
 public:
  virtual ~EncoderBackend() = default;
  virtual EncoderSource& encoder() noexcept = 0;
  // describe: one line for the start-up report.
  virtual const std::string& describe() const noexcept = 0;
};

// max_counts_per_s: the jump limit of [hctl1100].max_speed [m/s] in counts/s of this robot.
double max_counts_per_s(const Hctl1100Section& s, const KinematicParams& p);

// make_gpio_backend: [gpio] lines via libgpiod; errors name the config file and the line.
Result<std::unique_ptr<EncoderBackend>> make_gpio_backend(const Config& cfg);

// make_hctl_gpio_backend: [hctl1100] with bus = "gpio".
Result<std::unique_ptr<EncoderBackend>> make_hctl_gpio_backend(const Config& cfg,
                                                               const Kinematics& k);

// make_hctl_sim_backend: [hctl1100] with bus = "sim": two register models that follow `robot`
// at the time of `clock` minus `epoch`, on a simulated bus, read by the real driver.
Result<std::unique_ptr<EncoderBackend>> make_hctl_sim_backend(const Config& cfg,
                                                              const Kinematics& k,
                                                              sim::SimRobot& robot, Clock& clock,
                                                              TimeNs epoch);

// can_encoder_config: the driver configuration of [can_encoder] for this robot (layouts from
// the protocol, jump limit from max_speed, request period from request_rate; the wheels per side
// and their combination from [encoder], `w`).
drivers::CanEncoderConfig can_encoder_config(const CanEncoderSection& s, const SideWheelsConfig& w,
                                             const KinematicParams& p);

// make_can_socketcan_backend: [can_encoder] with bus = "socketcan": a raw socket on
// `interface` with kernel filters for the two wheel ids.
Result<std::unique_ptr<EncoderBackend>> make_can_socketcan_backend(const Config& cfg,
                                                                   const Kinematics& k);

// make_can_sim_backend: [can_encoder] with bus = "sim": two simulated ODrive axes publish the
// counts of `robot` (robot time = loop time minus `epoch`) every sim_period into a simulated
// bus port, read by the real driver; sim_stop_*_after stop an axis (fault).
Result<std::unique_ptr<EncoderBackend>> make_can_sim_backend(const Config& cfg, const Kinematics& k,
                                                             sim::SimRobot& robot, TimeNs epoch);

// serial_source_config: the source configuration of [serial] for this robot (wheels per side
// from [encoder], `w`) (jump limit from
// max_speed, poll period from poll_rate).
protocol::SerialSourceConfig serial_source_config(const SerialSection& s, const SideWheelsConfig& w,
                                                  const KinematicParams& p);

// make_serial_tty_backend: [serial] with link = "tty": the device in raw mode; a missing device,
// one that is not a tty, an unsupported baud rate: an error naming file, line and key.
Result<std::unique_ptr<EncoderBackend>> make_serial_tty_backend(const Config& cfg,
                                                                const Kinematics& k);

// make_serial_sim_backend: [serial] with link = "sim": a simulated controller speaking the
// protocol follows `robot` (robot time = loop time minus `epoch`), its bytes read by the real
// source through an in-memory link.
Result<std::unique_ptr<EncoderBackend>> make_serial_sim_backend(const Config& cfg,
                                                                const Kinematics& k,
                                                                sim::SimRobot& robot, TimeNs epoch);

}  // namespace odo::fw
