// GpioSim: one gpio-sim chip made through configfs for a kernel-tier test, with its lines'
// `pull` attributes (what drives an input) and `value` attributes (what an output drives).
// Inside the VM harness only; every step that fails says which file it was.
#pragma once

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace odo::test {

class GpioSim {
 public:
  // GpioSim: creates chip `name` with `lines` lines and brings it live (throws with the path
  // that failed; a test's set-up, not product code).
  GpioSim(const std::string& name, int lines) : dir_("/sys/kernel/config/gpio-sim/" + name) {
    mkdir_or_throw(dir_);
    mkdir_or_throw(dir_ + "/bank0");
    write_file(dir_ + "/bank0/num_lines", std::to_string(lines));
    write_file(dir_ + "/live", "1");
    const std::string dev = read_file(dir_ + "/dev_name");
    chip_ = read_file(dir_ + "/bank0/chip_name");
    const std::string base = "/sys/devices/platform/" + dev + "/" + chip_ + "/sim_gpio";
    for (int i = 0; i < lines; ++i) {
      const std::string p = base + std::to_string(i) + "/pull";
      const int fd = ::open(p.c_str(), O_RDWR);
      if (fd < 0) throw std::runtime_error(p + ": " + std::strerror(errno));
      pull_fd_.push_back(fd);
      value_path_.push_back(base + std::to_string(i) + "/value");
    }
  }
  ~GpioSim() {
    for (int fd : pull_fd_) ::close(fd);
    try {
      write_file(dir_ + "/live", "0");
    } catch (...) {
    }
    ::rmdir((dir_ + "/bank0").c_str());
    ::rmdir(dir_.c_str());
  }
  GpioSim(const GpioSim&) = delete;
  GpioSim& operator=(const GpioSim&) = delete;

  // chip: the character device, e.g. /dev/gpiochip1.
  std::string chip() const { return "/dev/" + chip_; }
  // pull: drive input line `line` high (pull-up) or low (pull-down); false on a write error.
  bool pull(int line, bool up) {
    const char* v = up ? "pull-up" : "pull-down";
    return ::pwrite(pull_fd_[static_cast<std::size_t>(line)], v, std::strlen(v), 0) > 0;
  }
  // value: the line's current level (for an output line: what the consumer drives); -1 on error.
  int value(int line) const {
    char c = 0;
    const int fd = ::open(value_path_[static_cast<std::size_t>(line)].c_str(), O_RDONLY);
    if (fd < 0) return -1;
    const ssize_t n = ::read(fd, &c, 1);
    ::close(fd);
    return n == 1 ? c - '0' : -1;
  }

 private:
  static void mkdir_or_throw(const std::string& p) {
    if (::mkdir(p.c_str(), 0755) != 0 && errno != EEXIST)
      throw std::runtime_error("mkdir " + p + ": " + std::strerror(errno));
  }
  static void write_file(const std::string& p, const std::string& v) {
    std::ofstream f(p);
    f << v;
    f.close();
    if (!f) throw std::runtime_error("write " + p + " = " + v + " failed");
  }
  static std::string read_file(const std::string& p) {
    std::ifstream f(p);
    std::string s;
    if (!(f >> s)) throw std::runtime_error("read " + p + " failed");
    return s;
  }

  std::string dir_;
  std::string chip_;
  std::vector<int> pull_fd_;
  std::vector<std::string> value_path_;
};

}  // namespace odo::test
