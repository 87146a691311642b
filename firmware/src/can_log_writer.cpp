#include "odo/firmware/can_log_writer.hpp"

#include <cerrno>
#include <chrono>
#include <cstring>

#include "odo/protocol/candump_log.hpp"

namespace odo::fw {

CanLogWriter::~CanLogWriter() {
  stop();
}

Result<std::unique_ptr<CanLogWriter>> CanLogWriter::open(const std::string& path,
                                                         std::string iface) {
  std::FILE* f = std::fopen(path.c_str(), "w");
  if (f == nullptr)
    return make_error(
        Errc::kIo, path + ": cannot open the CAN log for writing (" + std::strerror(errno) + ")");
  std::unique_ptr<CanLogWriter> w(new CanLogWriter(f, std::move(iface)));
  w->buffer_.resize(1 << 16);
  std::setvbuf(f, w->buffer_.data(), _IOFBF, w->buffer_.size());
  return w;
}

void CanLogWriter::start(std::int64_t epoch_ns) {
  epoch_ns_ = epoch_ns;
  thread_ = std::thread([this] {
    while (!stop_.load(std::memory_order_acquire)) {
      drain();
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
  });
}

void CanLogWriter::drain() noexcept {
  CanFrame f;
  char line[96];
  bool any = false;
  while (ring_.pop(f)) {
    const std::size_t n =
        protocol::format_candump_line(line, sizeof line, epoch_ns_ + f.stamp, iface_.c_str(), f);
    if (n > 0 && std::fwrite(line, 1, n, file_) == n) {
      written_.fetch_add(1, std::memory_order_relaxed);
      any = true;
    }
  }
  // A reader tails the log (odomctl decode, umbmark record --can-log): what was drained is in
  // the file now, whole lines, not when the 64 KiB buffer fills (issue 35: 8 s, then steps).
  // One write call per drain (every 20 ms) rather than one a frame.
  if (any) std::fflush(file_);
}

void CanLogWriter::stop() {
  stop_.store(true, std::memory_order_release);
  if (thread_.joinable()) thread_.join();
  if (file_ != nullptr) {
    drain();
    std::fclose(file_);
    file_ = nullptr;
  }
}

}  // namespace odo::fw
