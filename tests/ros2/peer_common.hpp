// Shared by the two test peers (Fast DDS and Cyclone DDS): argument parsing, the line format
// the integration test parses, and the latency summary. Plain C++, no DDS types.
#pragma once

#include <sys/resource.h>
#include <time.h>

#include <algorithm>
#include <cinttypes>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

namespace peer {

struct Args {
  int domain = 0;
  std::string ns;  // "" or "/name"
  int odom = 10;   // odom messages to receive before exiting
  int tf = 0;      // tf messages to receive before exiting
  bool set_pose = false;
  double sp_x = 0, sp_y = 0, sp_yaw = 0, sp_var = 0;  // the set_pose to publish
  double timeout_s = 20;
  bool quiet = false;  // print only the latency summary
  int skip = 0;        // first messages left out of the latency summary (discovery, warm-up)
  // > 0: run until no odom arrived for idle_s [s] (after the first), e.g. until the publishing
  // daemon exited; --odom N is then a minimum, and set_pose is not acknowledged at the end (the
  // publisher is gone): the caller checks in the data that it was applied.
  double idle_s = 0;
};

inline int usage(const char* argv0) {
  std::fprintf(stderr,
               "usage: %s --domain D [--ns /name] [--odom N] [--tf N] [--set-pose x y yaw var]\n"
               "          [--timeout s] [--quiet] [--skip N] [--idle s]\n",
               argv0);
  return 2;
}

// parse: false on a bad command line (usage printed by the caller).
inline bool parse(int argc, char** argv, Args& a) {
  for (int i = 1; i < argc; ++i) {
    const std::string k = argv[i];
    auto need = [&](int n) { return i + n < argc; };
    if (k == "--domain" && need(1)) {
      a.domain = std::atoi(argv[++i]);
    } else if (k == "--ns" && need(1)) {
      a.ns = argv[++i];
    } else if (k == "--odom" && need(1)) {
      a.odom = std::atoi(argv[++i]);
    } else if (k == "--tf" && need(1)) {
      a.tf = std::atoi(argv[++i]);
    } else if (k == "--set-pose" && need(4)) {
      a.set_pose = true;
      a.sp_x = std::atof(argv[++i]);
      a.sp_y = std::atof(argv[++i]);
      a.sp_yaw = std::atof(argv[++i]);
      a.sp_var = std::atof(argv[++i]);
    } else if (k == "--timeout" && need(1)) {
      a.timeout_s = std::atof(argv[++i]);
    } else if (k == "--quiet") {
      a.quiet = true;
    } else if (k == "--skip" && need(1)) {
      a.skip = std::atoi(argv[++i]);
    } else if (k == "--idle" && need(1)) {
      a.idle_s = std::atof(argv[++i]);
    } else {
      return false;
    }
  }
  return true;
}

inline std::int64_t realtime_ns() {
  timespec ts{};
  clock_gettime(CLOCK_REALTIME, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1000000000 + ts.tv_nsec;
}

inline double monotonic_s() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

// Line for one odom message: "odom sec nanosec recv_ns frame child x y z qx qy qz qw c[36] vx vy
// vz wx wy wz t[36]", doubles printed with %.17g (exact round trip).
inline void print_doubles(std::string& out, const double* v, int n) {
  char b[32];
  for (int i = 0; i < n; ++i) {
    std::snprintf(b, sizeof b, " %.17g", v[i]);
    out += b;
  }
}

// Latency from the header stamp (sample time in system time) to receipt, per message.
struct Latency {
  std::vector<std::int64_t> ns;
  int seen = 0;
  int skip = 0;
  void add(std::int32_t sec, std::uint32_t nanosec, std::int64_t recv) {
    if (seen++ < skip) return;
    ns.push_back(recv - (static_cast<std::int64_t>(sec) * 1000000000 + nanosec));
  }
  // summary: "latency n=.. p50_us=.. p99_us=.. max_us=.. cpu_us_per_msg=.." on stdout.
  void print_summary(int messages) {
    if (ns.empty()) return;
    std::sort(ns.begin(), ns.end());
    auto pct = [&](double p) {
      return ns[std::min(ns.size() - 1, static_cast<std::size_t>(p * (ns.size() - 1) + 0.5))];
    };
    rusage ru{};
    getrusage(RUSAGE_SELF, &ru);
    const double cpu_us = 1e6 * (ru.ru_utime.tv_sec + ru.ru_stime.tv_sec) +
                          (ru.ru_utime.tv_usec + ru.ru_stime.tv_usec);
    std::printf("latency n=%zu p50_us=%.1f p99_us=%.1f max_us=%.1f cpu_us_per_msg=%.1f\n",
                ns.size(), pct(0.5) / 1e3, pct(0.99) / 1e3, ns.back() / 1e3,
                cpu_us / std::max(1, messages));
  }
};

// Running: the receive loop's condition, counting odom receipts for --idle.
struct Running {
  double end = 0;        // monotonic deadline (--timeout)
  double last_odom = 0;  // monotonic time of the newest odom receipt, 0: none yet
  int seen = 0;
  // more: whether to keep receiving, given the counts so far.
  bool more(const Args& a, int n_odom, int n_tf) {
    const double now = monotonic_s();
    if (n_odom != seen) {
      seen = n_odom;
      last_odom = now;
    }
    if (now >= end) return false;
    if (a.idle_s > 0) return last_odom == 0 || now - last_odom < a.idle_s;
    return n_odom < a.odom || n_tf < a.tf;
  }
};

// finish: the closing lines (latency summary with --quiet, then "done ..."); returns the exit
// status: 0 when every expected message arrived and the set_pose (if any) was acknowledged.
inline int finish(const Args& a, Latency& lat, int n_odom, int n_tf, bool acked) {
  if (a.quiet) lat.print_summary(n_odom + n_tf);
  const bool unchecked = a.set_pose && a.idle_s > 0;
  std::printf("done odom=%d tf=%d set_pose_acked=%s\n", n_odom, n_tf,
              unchecked ? "unchecked" : (acked ? "1" : "0"));
  return (n_odom >= a.odom && n_tf >= a.tf && acked) ? 0 : 3;
}

}  // namespace peer
