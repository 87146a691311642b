// ros2_sim_publisher: the bridge fed by a simulated loop, for the latency measurement by hand
// (BENCHMARKS / docs-draft/ROS2.md). Loopback only: interfaces lo, no multicast, peer 127.0.0.1.
//   ros2_sim_publisher DOMAIN LOOP_HZ RATE_HZ SECONDS [tf 0|1]
#include <sys/resource.h>

#include <cstdio>
#include <cstdlib>

#include "odo/ros2/bridge.hpp"
#include "sim_source.hpp"

int main(int argc, char** argv) {
  if (argc < 5) {
    std::fprintf(stderr, "usage: %s DOMAIN LOOP_HZ RATE_HZ SECONDS [TF 0|1]\n", argv[0]);
    return 2;
  }
  odo::ros2::Config c;
  c.enabled = true;
  c.domain_id = static_cast<std::uint32_t>(std::atoi(argv[1]));
  const double loop_hz = std::atof(argv[2]);
  c.rate_hz = std::atof(argv[3]);
  const double seconds = std::atof(argv[4]);
  c.publish_tf = argc > 5 && std::atoi(argv[5]) != 0;
  c.interfaces = {"lo"};
  c.multicast = false;
  c.peers = {"127.0.0.1"};
  odo::ros2::test::SimLoop loop(loop_hz);
  auto b = odo::ros2::Bridge::create(
      c, loop_hz, [&](odo::ros2::OdomSample& s) { return loop.read(s); },
      [](const odo::ros2::PoseWithCovarianceFields& p) {
        const odo::Pose2& q = p.set_pose.pose;
        std::printf("set_pose %.17g %.17g %.17g\n", q.x, q.y, q.theta);
      });
  if (!b) {
    std::fprintf(stderr, "%s\n", b.error().message.c_str());
    return 1;
  }
  loop.start();
  if (auto s = (*b)->start(); !s) return std::fprintf(stderr, "%s\n", s.error().message.c_str()), 1;
  timespec d{static_cast<time_t>(seconds),
             static_cast<long>((seconds - static_cast<time_t>(seconds)) * 1e9)};
  nanosleep(&d, nullptr);
  (*b)->stop();
  loop.stop();
  const auto st = (*b)->stats();
  rusage ru{};
  getrusage(RUSAGE_SELF, &ru);
  const double cpu_us = 1e6 * static_cast<double>(ru.ru_utime.tv_sec + ru.ru_stime.tv_sec) +
                        static_cast<double>(ru.ru_utime.tv_usec + ru.ru_stime.tv_usec);
  const double n = static_cast<double>(std::max<std::uint64_t>(1, st.odom_published));
  std::printf("write age (sample -> dds_write returned): mean_us=%.1f max_us=%.1f\n",
              static_cast<double>(st.write_age_sum_ns) / n / 1e3,
              static_cast<double>(st.write_age_max_ns) / 1e3);
  std::printf(
      "published odom=%llu tf=%llu errors=%llu cpu_us_per_msg=%.1f (whole process, sim loop "
      "included)\n",
      static_cast<unsigned long long>(st.odom_published),
      static_cast<unsigned long long>(st.tf_published),
      static_cast<unsigned long long>(st.write_errors),
      cpu_us /
          static_cast<double>(std::max<std::uint64_t>(1, st.odom_published + st.tf_published)));
  return 0;
}
