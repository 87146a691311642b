#include "odo/drivers/serial_port.hpp"

#include "odo/drivers/monotonic_clock.hpp"

#include <fcntl.h>
#include <poll.h>
#include <sys/stat.h>
#include <termios.h>
#include <unistd.h>

#include <array>
#include <atomic>
#include <cerrno>
#include <cstring>
#include <mutex>
#include <thread>

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

struct SerialPort::Impl {
  struct Chunk {
    TimeNs stamp = 0;
    int len = 0;  // -1: the device vanished here
    std::array<std::uint8_t, 64> data{};
  };
  std::string path;
  speed_t code{};
  TimeNs reopen_period = 0;
  std::mutex fd_mutex;  // the thread holds it to close / reopen; write() only try-locks it
  int fd = -1;
  std::atomic<bool> open{false};
  std::atomic<bool> stop{false};
  std::array<Chunk, 256> ring{};
  std::atomic<std::size_t> head{0};  // written by the thread
  std::atomic<std::size_t> tail{0};  // written by the loop
  std::size_t taken = 0;             // loop: bytes of ring[tail] already returned
  std::atomic<std::uint64_t> dropped{0};
  std::thread thread;

  void push(TimeNs t, const std::uint8_t* d, int len) noexcept {
    const std::size_t h = head.load(std::memory_order_relaxed);
    if (h - tail.load(std::memory_order_acquire) >= ring.size()) {
      dropped.fetch_add(1, std::memory_order_relaxed);  // the loop is not draining: drop newest
      return;
    }
    Chunk& c = ring[h % ring.size()];
    c.stamp = t;
    c.len = len;
    if (len > 0) std::memcpy(c.data.data(), d, static_cast<std::size_t>(len));
    head.store(h + 1, std::memory_order_release);
  }
  void gone(int f) noexcept {
    std::lock_guard<std::mutex> lk(fd_mutex);
    ::close(f);
    fd = -1;
    open.store(false);
    push(monotonic_now(), nullptr, -1);
  }
  void wait_and_reopen() noexcept {
    // Sleep the reopen period in 20 ms steps (stop stays prompt), then try the path again.
    for (TimeNs slept = 0; slept < reopen_period && !stop.load(); slept += 20'000'000)
      ::usleep(20'000);
    const int f = open_raw(path, code);
    if (f < 0) return;
    std::lock_guard<std::mutex> lk(fd_mutex);
    fd = f;
    open.store(true);
  }
  void run() noexcept {
    while (!stop.load()) {
      const int f = fd;  // only this thread changes fd
      if (f < 0) {
        wait_and_reopen();
        continue;
      }
      pollfd p{f, POLLIN, 0};
      if (::poll(&p, 1, 50) <= 0) continue;  // 50 ms: stop is seen promptly
      std::array<std::uint8_t, 64> buf{};
      const ssize_t n = ::read(f, buf.data(), buf.size());
      const TimeNs t = monotonic_now();
      if (n > 0)
        push(t, buf.data(), static_cast<int>(n));
      else if (n < 0 && (errno == EAGAIN || errno == EINTR))
        continue;
      else  // 0 (hang-up) or EIO / ENODEV / ENXIO: unplugged, or the pty's master closed
        gone(f);
    }
  }
};

Result<std::unique_ptr<SerialPort>> SerialPort::open(const std::string& path, int baud,
                                                     TimeNs reopen_period) {
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
  auto impl = std::make_unique<Impl>();
  impl->path = path;
  impl->code = code;
  impl->reopen_period = reopen_period;
  impl->fd = fd;
  impl->open.store(true);
  Impl* raw = impl.get();
  impl->thread = std::thread([raw] { raw->run(); });
  return std::unique_ptr<SerialPort>(new SerialPort(std::move(impl)));
}

SerialPort::SerialPort(std::unique_ptr<Impl> impl) noexcept : impl_(std::move(impl)) {}

SerialPort::~SerialPort() {
  impl_->stop.store(true);
  if (impl_->thread.joinable()) impl_->thread.join();
  if (impl_->fd >= 0) ::close(impl_->fd);
}

int SerialPort::read(std::span<std::uint8_t> out, TimeNs& arrival) noexcept {
  Impl& m = *impl_;
  const std::size_t t = m.tail.load(std::memory_order_relaxed);
  if (t == m.head.load(std::memory_order_acquire)) return 0;
  const Impl::Chunk& c = m.ring[t % m.ring.size()];
  int n = -1;
  if (c.len >= 0) {
    n = static_cast<int>(
        std::min<std::size_t>(out.size(), static_cast<std::size_t>(c.len) - m.taken));
    std::memcpy(out.data(), c.data.data() + m.taken, static_cast<std::size_t>(n));
    arrival = c.stamp;
    m.taken += static_cast<std::size_t>(n);
    if (m.taken < static_cast<std::size_t>(c.len)) return n;
  }
  m.taken = 0;
  m.tail.store(t + 1, std::memory_order_release);
  return n;
}

bool SerialPort::write(std::span<const std::uint8_t> data) noexcept {
  // Never wait for the thread: while it closes or reopens the device the request is dropped.
  std::unique_lock<std::mutex> lk(impl_->fd_mutex, std::try_to_lock);
  if (!lk.owns_lock() || impl_->fd < 0) return false;
  const ssize_t n = ::write(impl_->fd, data.data(), data.size());
  return n == static_cast<ssize_t>(data.size());
}

bool SerialPort::reopen() noexcept {
  return impl_->open.load();
}

std::uint64_t SerialPort::dropped() const noexcept {
  return impl_->dropped.load();
}

}  // namespace odo::drivers
