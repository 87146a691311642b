// serial_peer: a simulated microcontroller behind a kernel pseudo-terminal, a separate process
// for the serial backend's tests and demos (issue 37). It speaks diffodom (a record every
// --period) or arduino-bridge (answers "e\r" / "r\r" as ros_arduino_bridge's firmware documents
// them), publishes the pty's slave under the path --link (a symlink, as udev's
// /dev/serial/by-id links are), and writes every sample it sends as `t,left,right` (the wheels'
// physical counts) to --log for `odomctl replay`.
//
// Motion: the wheels move in steps every --step-every seconds (a different step each time) and
// stand still in between, and around every fault: a tick of odometryd then integrates either
// nothing or exactly one step, as a replay of the log does: the poses are equal to the bit.
// Faults: --unplug-at T (the pty is closed, gone for --unplug-for s, then a new pty under the
// same link: another /dev/pts name), --garbage-at T (a burst of garbage bytes), --reset-at T
// (the controller reboots: counters, clock and sequence restart at 0, the booted flag), and
// --silent (never answers / never sends: a board that does not talk).
//
// usage: serial_peer --link PATH --protocol diffodom|arduino-bridge --duration S [--period S]
//        [--step-every S] [--move-until S] [--unplug-at T] [--unplug-for S] [--garbage-at T]...
//        [--reset-at T] [--start-after S] [--log FILE] [--silent]
#include <fcntl.h>
#include <poll.h>
#include <termios.h>
#include <unistd.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <string>
#include <vector>

#include "odo/firmware/serial_peer.hpp"

namespace {

struct Options {
  std::string link, log;
  odo::fw::SerialProtocol protocol = odo::fw::SerialProtocol::kDiffodom;
  double duration = 5, period = 0.01, step_every = 0.2, move_until = 1e9, start_after = 1.0;
  double unplug_at = -1, unplug_for = 0.5, reset_at = -1;
  std::vector<double> garbage_at;
  bool silent = false;
};

double now_s() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<double>(ts.tv_sec) + static_cast<double>(ts.tv_nsec) * 1e-9;
}

// open_pty: a new pty in raw mode (no echo, no line discipline), its slave linked at `link`.
int open_pty(const std::string& link) {
  const int m = posix_openpt(O_RDWR | O_NOCTTY | O_NONBLOCK);
  if (m < 0 || grantpt(m) != 0 || unlockpt(m) != 0) return -1;
  termios t{};
  tcgetattr(m, &t);
  cfmakeraw(&t);
  tcsetattr(m, TCSANOW, &t);
  const std::string tmp = link + ".new";
  ::unlink(tmp.c_str());
  if (symlink(ptsname(m), tmp.c_str()) != 0 || rename(tmp.c_str(), link.c_str()) != 0) {
    std::perror("serial_peer: link");
    return -1;
  }
  std::fprintf(stderr, "serial_peer: %s -> %s\n", link.c_str(), ptsname(m));
  return m;
}

bool parse(int argc, char** argv, Options& o) {
  for (int i = 1; i + 1 < argc || (i < argc && !std::strcmp(argv[i], "--silent")); i += 2) {
    const std::string k = argv[i];
    if (k == "--silent") {
      o.silent = true;
      --i;
      continue;
    }
    const char* v = argv[i + 1];
    if (k == "--link")
      o.link = v;
    else if (k == "--log")
      o.log = v;
    else if (k == "--protocol")
      o.protocol = std::string(v) == "arduino-bridge" ? odo::fw::SerialProtocol::kArduinoBridge
                                                      : odo::fw::SerialProtocol::kDiffodom;
    else if (k == "--duration")
      o.duration = std::atof(v);
    else if (k == "--period")
      o.period = std::atof(v);
    else if (k == "--step-every")
      o.step_every = std::atof(v);
    else if (k == "--move-until")
      o.move_until = std::atof(v);
    else if (k == "--start-after")
      o.start_after = std::atof(v);
    else if (k == "--unplug-at")
      o.unplug_at = std::atof(v);
    else if (k == "--unplug-for")
      o.unplug_for = std::atof(v);
    else if (k == "--reset-at")
      o.reset_at = std::atof(v);
    else if (k == "--garbage-at")
      o.garbage_at.push_back(std::atof(v));
    else
      return false;
  }
  return !o.link.empty();
}

// quiet_at: no step near a fault (0.3 s before to 0.6 s after; an unplug's whole absence).
bool quiet_at(const Options& o, double t) {
  auto near = [&](double at, double len) { return at >= 0 && t > at - 0.3 && t < at + len + 0.6; };
  if (near(o.unplug_at, o.unplug_for) || near(o.reset_at, 0)) return true;
  for (double g : o.garbage_at)
    if (near(g, 0)) return true;
  return t < o.start_after || t >= o.move_until;  // still while the host opens the line
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  if (!parse(argc, argv, o)) {
    std::fprintf(stderr, "usage: serial_peer --link PATH [--protocol P] --duration S ...\n");
    return 2;
  }
  std::FILE* log = o.log.empty() ? nullptr : std::fopen(o.log.c_str(), "w");
  if (log) std::fprintf(log, "t,left,right\n");
  int m = open_pty(o.link);
  if (m < 0) return 1;
  odo::fw::SerialPeerModel model(o.protocol);
  // The board has been counting before: physical counts start away from 0.
  std::int64_t left = 100000, right = -50000;
  int k = 0;
  const double t0 = now_s();
  double next_step = o.step_every, next_send = 0;
  std::size_t garbage_done = 0;
  bool unplugged = false, reset_done = false;
  std::srand(37);
  for (;;) {
    const double t = now_s() - t0;
    if (t >= o.duration) break;
    const auto tn = static_cast<odo::TimeNs>(t * 1e9);
    while (t >= next_step) {  // the wheels move one step (both at once: one sample sees it)
      if (!quiet_at(o, next_step)) {
        left += 300 + (k * 37) % 200;
        right += 250 + (k * 53) % 300 - (k % 4 == 0 ? 600 : 0);
        ++k;
      }
      next_step += o.step_every;
    }
    if (o.reset_at >= 0 && !reset_done && t >= o.reset_at) {
      model.reset(tn, left, right);
      reset_done = true;
    }
    if (o.unplug_at >= 0 && !unplugged && t >= o.unplug_at) {
      ::close(m);
      ::unlink(o.link.c_str());
      usleep(static_cast<useconds_t>(o.unplug_for * 1e6));
      m = open_pty(o.link);
      if (m < 0) return 1;
      unplugged = true;
      continue;
    }
    std::array<std::uint8_t, odo::fw::SerialPeerModel::kMaxOut> out{};
    if (garbage_done < o.garbage_at.size() && t >= o.garbage_at[garbage_done]) {
      std::array<std::uint8_t, 48> g{};
      for (auto& b : g) b = static_cast<std::uint8_t>(0x80 + std::rand() % 0x7F);
      g[20] = o.protocol == odo::fw::SerialProtocol::kDiffodom ? 0 : '\n';
      g[47] = g[20];
      if (::write(m, g.data(), g.size()) < 0) { /* nobody reading: dropped */
      }
      ++garbage_done;
    }
    std::array<std::uint8_t, 64> in{};
    const ssize_t n = ::read(m, in.data(), in.size());
    if (n > 0)
      model.on_host_bytes(std::span<const std::uint8_t>(in.data(), static_cast<std::size_t>(n)));
    std::size_t len = 0;
    if (o.protocol == odo::fw::SerialProtocol::kDiffodom) {
      if (t >= next_send) {
        next_send += o.period;
        len = model.sample(tn, left, right, out);
      }
    } else {
      len = model.sample(tn, left, right, out);
    }
    if (len > 0 && !o.silent) {
      if (::write(m, out.data(), len) == static_cast<ssize_t>(len) && log)
        std::fprintf(log, "%.6f,%lld,%lld\n", t, static_cast<long long>(left),
                     static_cast<long long>(right));
    }
    pollfd p{m, POLLIN, 0};
    ::poll(&p, 1, 1);  // 1 ms: requests are answered within about that
  }
  if (log) std::fclose(log);
  ::close(m);
  ::unlink(o.link.c_str());
  return 0;
}
