// IioGyro: a MEMS rate gyro through the Linux IIO subsystem as a YawRateSource.
//
// Two modes:
// - kBuffered (the default): the driver samples at its own rate (data-ready interrupt or a
//   trigger), time-stamps each scan when it is taken, and queues it in the kernel buffer;
//   read() drains /dev/iio:deviceN without blocking and averages every sample that arrived since
//   the last tick. Nothing on the loop path waits for the bus; no sample is lost between ticks;
//   the time stamps are the driver's (current_timestamp_clock is set to "monotonic", the loop's
//   clock).
// - kPolled: read() reads in_anglvel_<axis>_raw through sysfs. Every read is a synchronous bus
//   transaction in the loop thread (a 2-byte I2C read at 400 kHz is >= 100 us plus the driver's
//   runtime-PM wake-up), it sees one sample per tick whatever the gyro's rate, and its time
//   stamp is the loop's `now`. For devices without a usable trigger (no interrupt line wired:
//   most drivers then register no trigger at all) it is the only choice.
// The loop should use kBuffered wherever the device has a trigger; BENCHMARKS/tests/kernel
// measure both.
//
// Channel: in_anglvel_<axis> of the device; rate = sign * (raw + offset) * scale [rad/s], with
// scale and offset from in_anglvel_<axis>_scale / in_anglvel_scale and ..._offset (0 if absent),
// read once at open. The mounting sign turns the chip's axis into the robot's z (CCW positive).
// Errors at open name the device (name and sysfs directory) and the channel or attribute.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "odo/drivers/iio_scan.hpp"
#include "odo/hal/gyro.hpp"
#include "odo/hal/result.hpp"

namespace odo::drivers {

enum class IioMode : std::uint8_t { kBuffered, kPolled };
enum class IioAxis : std::uint8_t { kX, kY, kZ };

struct IioGyroConfig {
  std::string device;  // the device's name (sysfs `name`), its sysfs directory, or /dev/iio:deviceN
  IioAxis axis = IioAxis::kZ;  // the chip axis that points along the robot's z
  int sign = 1;                // +1: chip axis up; -1: chip mounted upside down
  IioMode mode = IioMode::kBuffered;
  double expected_rate = 0.0;         // sampling frequency to set and check [Hz]; 0: leave it
  std::string trigger;                // trigger to attach (trigger/current_trigger); "": leave it
  int buffer_length = 256;            // scans the kernel buffer holds (buffer/length)
  TimeNs stale_timeout = 50'000'000;  // no sample for this long: kGyroStale [ns]
  int max_scans_per_read = 64;        // scans taken per read(); the rest waits for the next
  std::string sysfs_root = "/sys/bus/iio/devices";  // tests point these at a fake tree
  std::string dev_root = "/dev";
};

// axis_letter: 'x', 'y' or 'z'.
char axis_letter(IioAxis a) noexcept;

class IioGyro final : public YawRateSource {
 public:
  // open: finds the device, checks the channel, reads scale and offset and (buffered) sets up
  // the scan elements, timestamp clock, trigger and buffer, then opens the character device.
  static Result<std::unique_ptr<IioGyro>> open(const IioGyroConfig& c);
  ~IioGyro() override;
  IioGyro(const IioGyro&) = delete;
  IioGyro& operator=(const IioGyro&) = delete;

  GyroSample read(TimeNs now) noexcept override;
  // full_scale: the rate of the largest raw word [rad/s]; infinity when the word's width is
  // unknown (polled mode on a device without scan elements).
  double full_scale() const noexcept override { return full_scale_; }

  const std::string& device_dir() const noexcept { return dir_; }  // sysfs directory
  const std::string& name() const noexcept { return name_; }       // the device's name
  double scale() const noexcept { return scale_; }                 // [rad/s per LSB]
  double offset() const noexcept { return offset_; }               // [LSB]
  std::size_t scan_bytes() const noexcept { return scan_bytes_; }

 private:
  IioGyro() = default;
  Status setup_buffer(const IioGyroConfig& c);
  Status setup_polled(const IioGyroConfig& c);
  Status read_scale(const IioGyroConfig& c);
  Status layout(const std::string& who, const std::string& scan_elements);
  Status configure_rate_and_trigger(const IioGyroConfig& c, const std::string& who);
  // read_buffered / read_polled: the sum of the raw words read (count in s.samples).
  double read_buffered(GyroSample& s) noexcept;
  double read_polled(GyroSample& s, TimeNs now) noexcept;
  void finish(GyroSample& s, TimeNs now, double sum) noexcept;

  std::string dir_, name_, chan_;
  IioMode mode_ = IioMode::kBuffered;
  int fd_ = -1;  // /dev/iio:deviceN (buffered) or in_anglvel_<axis>_raw (polled)
  double sign_ = 1.0, scale_ = 0.0, offset_ = 0.0;
  double full_scale_ = 0.0;
  IioScanType type_{}, ts_type_{};
  bool have_type_ = false;
  std::int64_t raw_lo_ = 0, raw_hi_ = 0;
  std::size_t scan_bytes_ = 0, rate_off_ = 0, ts_off_ = 0;
  std::vector<std::uint8_t> buf_;  // max_scans_per_read scans, allocated at open
  std::size_t pending_ = 0;        // bytes of an incomplete scan kept from the last read
  GyroReadBook book_;
};

}  // namespace odo::drivers
