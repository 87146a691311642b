// Output files written whole or not at all, paths checked before work, a progress line.
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <vector>

#include "commands.hpp"

namespace odo::ctl {

namespace {

std::string parent_dir(const std::string& path) {
  const std::string d = std::filesystem::path(path).parent_path().string();
  return d.empty() ? "." : d;
}

double now_s() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

}  // namespace

std::string output_path_problem(const std::string& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) return path + ": is a directory";
  const bool exists = std::filesystem::exists(path, ec);
  // An existing file must be writable; a new one needs a writable directory (the temporary
  // file and the rename of write_output_file happen there too).
  const std::string dir = parent_dir(path);
  if (exists && ::access(path.c_str(), W_OK) != 0)
    return path + ": cannot write: " + std::strerror(errno);
  if (::access(dir.c_str(), W_OK | X_OK) != 0)
    return path + ": cannot create: " + std::strerror(errno);
  return {};
}

bool output_paths_ok(std::initializer_list<std::string> paths, const char* cmd) {
  for (const std::string& p : paths) {
    if (p.empty()) continue;
    if (std::string m = output_path_problem(p); !m.empty()) {
      std::cerr << "odomctl " << cmd << ": " << m << "\n";
      return false;
    }
  }
  return true;
}

bool write_output_file(const std::string& path, const std::string& text, const char* cmd) {
  std::string tmpl = path + ".XXXXXX";
  std::vector<char> name(tmpl.begin(), tmpl.end());
  name.push_back('\0');
  const int fd = ::mkstemp(name.data());
  const auto fail = [&](int err) {
    std::cerr << "odomctl " << cmd << ": " << path << ": cannot write: " << std::strerror(err)
              << "\n";
    return false;
  };
  if (fd < 0) return fail(errno);
  std::size_t done = 0;
  while (done < text.size()) {
    const ssize_t n = ::write(fd, text.data() + done, text.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;
    done += static_cast<std::size_t>(n);
  }
  const int err = done == text.size() ? 0 : errno;
  // mkstemp creates 0600; an output file is for everyone to read, as ofstream's would be.
  const int rc = err == 0 ? ::fchmod(fd, 0644) | ::fsync(fd) : -1;
  ::close(fd);
  if (rc != 0 || std::rename(name.data(), path.c_str()) != 0) {
    const int e = err != 0 ? err : errno;
    std::remove(name.data());
    return fail(e);
  }
  return true;
}

ProgressLine::ProgressLine(std::string what)
    : what_(std::move(what)), tty_(::isatty(STDERR_FILENO) == 1), start_(now_s()) {}

void ProgressLine::update(int done, int total) {
  if (!tty_ || total <= 0) return;
  const double spent = now_s() - start_;
  const double left = done > 0 ? spent * (total - done) / done : 0.0;
  // \r and clear-to-end-of-line (ESC [K): the line is rewritten in place.
  std::fprintf(stderr, "\r  %d/%d %s, %.0f s left\x1b[K", done, total, what_.c_str(), left);
  std::fflush(stderr);
  shown_ = true;
}

void ProgressLine::finish() {
  if (shown_) std::fputs("\r\x1b[K", stderr);
  shown_ = false;
}

}  // namespace odo::ctl
