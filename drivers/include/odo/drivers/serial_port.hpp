// SerialPort: a tty (UART, USB CDC-ACM, a pseudo-terminal) as a ByteLink: raw mode (termios:
// no echo, no line editing, no translation, 8N1, no flow control). A reader thread of its own
// waits on the tty and stamps every chunk it reads with CLOCK_MONOTONIC (the loop's clock) the
// moment it arrives, into a fixed ring the loop thread drains without waiting or allocating:
// the sample times are the bytes' arrival, not the loop tick that reads them (BENCHMARKS.md
// "Serial counts: sample times": 11 mm/s rms of v at 100 Hz from tick-quantised arrivals, 0.5
// with the thread's stamps). A device that vanishes (EIO, ENODEV, hang-up) is closed by the
// thread, which reports it in the ring and opens the same path again every reopen period,
// following symlinks such as /dev/serial/by-id/..., so a board that comes back under another
// ttyACM name is found.
#pragma once

#include <memory>
#include <span>
#include <string>

#include "odo/hal/time.hpp"

#include "odo/hal/byte_link.hpp"
#include "odo/hal/result.hpp"

namespace odo::drivers {

// kSerialBaudRates: the rates a SerialPort can set [baud]; any other is refused.
inline constexpr int kSerialBaudRates[] = {9600,   19200,  38400,  57600,   115200,  230400, 460800,
                                           500000, 576000, 921600, 1000000, 1500000, 2000000};
// supported_baud: baud is one of kSerialBaudRates.
bool supported_baud(int baud) noexcept;
// baud_list: "9600, 19200, ...", for messages.
std::string baud_list();

class SerialPort final : public ByteLink {
 public:
  // open: the tty at `path` in raw mode at `baud`, its reader thread started (a vanished device
  // is tried again every `reopen_period` [ns]); errors say which: no such device, not a tty,
  // unsupported baud rate, permission.
  static Result<std::unique_ptr<SerialPort>> open(const std::string& path, int baud,
                                                  TimeNs reopen_period = 500'000'000);
  ~SerialPort() override;
  SerialPort(const SerialPort&) = delete;
  SerialPort& operator=(const SerialPort&) = delete;

  // read: the bytes of the oldest chunk not yet taken (up to out.size(); the rest next call),
  // `arrival` its stamp; -1 once where the device vanished in the stream.
  int read(std::span<std::uint8_t> out, TimeNs& arrival) noexcept override;
  bool write(std::span<const std::uint8_t> data) noexcept override;
  // reopen: true once the reader thread has the device open again.
  bool reopen() noexcept override;
  // dropped: chunks lost because the loop did not drain the ring in time.
  std::uint64_t dropped() const noexcept;

  struct Impl;

 private:
  explicit SerialPort(std::unique_ptr<Impl> impl) noexcept;
  std::unique_ptr<Impl> impl_;
};

}  // namespace odo::drivers
