#include "odo/drivers/serial_port.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <termios.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

namespace odo::drivers {
namespace {

struct BaudCode {
  int baud;
  speed_t code;
};
// One entry per kSerialBaudRates entry (checked below).
constexpr BaudCode kBaudCodes[] = {{9600, B9600},      {19200, B19200},     {38400, B38400},
                                   {57600, B57600},    {115200, B115200},   {230400, B230400},
                                   {460800, B460800},  {500000, B500000},   {576000, B576000},
                                   {921600, B921600},  {1000000, B1000000}, {1500000, B1500000},
                                   {2000000, B2000000}};
static_assert(std::size(kBaudCodes) == std::size(kSerialBaudRates));

bool baud_code(int baud, speed_t& out) noexcept {
  for (const BaudCode& b : kBaudCodes)
    if (b.baud == baud) {
      out = b.code;
      return true;
    }
  return false;
}

// open_raw: the tty opened non-blocking and set to raw 8N1 at `code`; -1 with errno, or -2
// when it is not a tty.
int open_raw(const std::string& path, speed_t code) noexcept {
  const int fd = ::open(path.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) return -1;
  termios t{};
  if (!::isatty(fd) || ::tcgetattr(fd, &t) != 0) {
    ::close(fd);
    return -2;
  }
  ::cfmakeraw(&t);
  t.c_cflag |= CLOCAL | CREAD;
  t.c_cflag &= ~static_cast<tcflag_t>(CSTOPB | CRTSCTS);
  t.c_iflag &= ~static_cast<tcflag_t>(IXON | IXOFF | IXANY);
  // VMIN 1 with O_NONBLOCK: no data is EAGAIN, so that a read of 0 means hang-up only (with
  // VMIN 0 a read returns 0 whenever nothing is there, indistinguishable from an unplugged board).
  t.c_cc[VMIN] = 1;
  t.c_cc[VTIME] = 0;
  ::cfsetispeed(&t, code);
  ::cfsetospeed(&t, code);
  if (::tcsetattr(fd, TCSANOW, &t) != 0) {
    const int e = errno;
    ::close(fd);
    errno = e;
    return -1;
  }
  ::tcflush(fd, TCIOFLUSH);  // bytes from before this open belong to no one
  return fd;
}

}  // namespace

bool supported_baud(int baud) noexcept {
  speed_t c{};
  return baud_code(baud, c);
}

std::string baud_list() {
  std::string s;
  for (const int b : kSerialBaudRates) s += (s.empty() ? "" : ", ") + std::to_string(b);
  return s;
}

Result<std::unique_ptr<SerialPort>> SerialPort::open(const std::string& path, int baud) {
  speed_t code{};
  if (!baud_code(baud, code))
    return make_error(
        Errc::kInvalidArgument,
        "baud = " + std::to_string(baud) + " is not a supported baud rate (" + baud_list() + ")");
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0)
    return make_error(Errc::kNotFound, "device = \"" + path + "\": " + std::strerror(errno) +
                                           " (is the board plugged in?)");
  if (!S_ISCHR(st.st_mode))
    return make_error(Errc::kInvalidArgument, "device = \"" + path + "\" is not a tty");
  const int fd = open_raw(path, code);
  if (fd == -2) return make_error(Errc::kInvalidArgument, "device = \"" + path + "\" is not a tty");
  if (fd < 0)
    return make_error(Errc::kIo, "device = \"" + path + "\": cannot open: " + std::strerror(errno));
  return std::unique_ptr<SerialPort>(new SerialPort(path, baud, fd));
}

SerialPort::~SerialPort() {
  close_fd();
}

void SerialPort::close_fd() noexcept {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
}

int SerialPort::read(std::span<std::uint8_t> out) noexcept {
  if (fd_ < 0) return -1;
  for (;;) {
    const ssize_t n = ::read(fd_, out.data(), out.size());
    if (n > 0) return static_cast<int>(n);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) return 0;
    // 0 (hang-up) or EIO / ENODEV / ENXIO: the device is gone (unplugged, pty master closed).
    close_fd();
    return -1;
  }
}

bool SerialPort::write(std::span<const std::uint8_t> data) noexcept {
  if (fd_ < 0) return false;
  const ssize_t n = ::write(fd_, data.data(), data.size());
  return n == static_cast<ssize_t>(data.size());
}

bool SerialPort::reopen() noexcept {
  close_fd();
  speed_t code{};
  baud_code(baud_, code);
  fd_ = open_raw(path_, code);
  if (fd_ < 0) fd_ = -1;
  return fd_ >= 0;
}

}  // namespace odo::drivers
