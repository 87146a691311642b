// SerialPort: a tty (UART, USB CDC-ACM, a pseudo-terminal) as a ByteLink: raw mode (termios:
// no echo, no line editing, no translation, 8N1, no flow control), non-blocking. A device that
// vanishes (EIO, ENODEV, hang-up) is closed; reopen() opens the same path again, following
// symlinks such as /dev/serial/by-id/..., so a board that comes back under another ttyACM name
// is found.
#pragma once

#include <memory>
#include <span>
#include <string>

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
  // open: the tty at `path` in raw mode at `baud`; errors say which: no such device, not a tty,
  // unsupported baud rate, permission.
  static Result<std::unique_ptr<SerialPort>> open(const std::string& path, int baud);
  ~SerialPort() override;
  SerialPort(const SerialPort&) = delete;
  SerialPort& operator=(const SerialPort&) = delete;

  int read(std::span<std::uint8_t> out) noexcept override;
  bool write(std::span<const std::uint8_t> data) noexcept override;
  bool reopen() noexcept override;

 private:
  SerialPort(std::string path, int baud, int fd) : path_(std::move(path)), baud_(baud), fd_(fd) {}
  void close_fd() noexcept;
  std::string path_;
  int baud_;
  int fd_;
};

}  // namespace odo::drivers
