// Second receiver on Cyclone DDS's C API (separate process, the library's IDL compiled by idlc):
// receives rt<ns>/odom and rt/tf, prints them in peer_common.hpp's format or a latency summary,
// and publishes rt<ns>/set_pose. Network set-up from CYCLONEDDS_URI (the test sets loopback).
#include <dds/dds.h>

#include <cmath>

#include "peer_common.hpp"
#include "ros2_msgs.h"
#include "tsan_suppressions.hpp"

namespace {

dds_qos_t* ros_qos() {
  dds_qos_t* q = dds_create_qos();
  dds_qset_reliability(q, DDS_RELIABILITY_RELIABLE, DDS_MSECS(100));
  dds_qset_durability(q, DDS_DURABILITY_VOLATILE);
  dds_qset_history(q, DDS_HISTORY_KEEP_LAST, 10);
  return q;
}

std::string odom_line(const nav_msgs_msg_dds__Odometry_& o, std::int64_t recv) {
  char b[160];
  std::snprintf(b, sizeof b, "odom %d %u %" PRId64 " %s %s", o.header.stamp.sec,
                o.header.stamp.nanosec, recv, o.header.frame_id, o.child_frame_id);
  std::string s = b;
  const auto& p = o.pose.pose;
  const double pose[] = {p.position.x,    p.position.y,    p.position.z,   p.orientation.x,
                         p.orientation.y, p.orientation.z, p.orientation.w};
  peer::print_doubles(s, pose, 7);
  peer::print_doubles(s, o.pose.covariance, 36);
  const auto& t = o.twist.twist;
  const double tw[] = {t.linear.x, t.linear.y, t.linear.z, t.angular.x, t.angular.y, t.angular.z};
  peer::print_doubles(s, tw, 6);
  peer::print_doubles(s, o.twist.covariance, 36);
  return s;
}

std::string tf_line(const tf2_msgs_msg_dds__TFMessage_& m, std::int64_t recv) {
  std::string s;
  for (uint32_t i = 0; i < m.transforms._length; ++i) {
    const auto& t = m.transforms._buffer[i];
    char b[160];
    std::snprintf(b, sizeof b, "tf %d %u %" PRId64 " %s %s", t.header.stamp.sec,
                  t.header.stamp.nanosec, recv, t.header.frame_id, t.child_frame_id);
    s += b;
    const auto& x = t.transform;
    const double v[] = {x.translation.x, x.translation.y, x.translation.z, x.rotation.x,
                        x.rotation.y,    x.rotation.z,    x.rotation.w};
    peer::print_doubles(s, v, 7);
  }
  return s;
}

struct Endpoints {
  dds_entity_t dp = 0, odom_r = 0, tf_r = 0, sp_w = 0, ws = 0;
};

// open: participant, the two readers and the set_pose writer with ROS 2's default QoS, and a
// waitset on the readers' data; false (message printed) on failure.
bool open(const peer::Args& a, Endpoints& e) {
  e.dp = dds_create_participant(a.domain, nullptr, nullptr);
  if (e.dp < 0) return std::fprintf(stderr, "cyclone_peer: %s\n", dds_strretcode(e.dp)), false;
  dds_qos_t* q = ros_qos();
  const std::string odom_name = "rt" + a.ns + "/odom", sp_name = "rt" + a.ns + "/set_pose";
  const dds_entity_t odom_t = dds_create_topic(e.dp, &nav_msgs_msg_dds__Odometry__desc,
                                               odom_name.c_str(), nullptr, nullptr);
  const dds_entity_t tf_t =
      dds_create_topic(e.dp, &tf2_msgs_msg_dds__TFMessage__desc, "rt/tf", nullptr, nullptr);
  const dds_entity_t sp_t =
      dds_create_topic(e.dp, &geometry_msgs_msg_dds__PoseWithCovarianceStamped__desc,
                       sp_name.c_str(), nullptr, nullptr);
  e.odom_r = dds_create_reader(e.dp, odom_t, q, nullptr);
  e.tf_r = dds_create_reader(e.dp, tf_t, q, nullptr);
  e.sp_w = dds_create_writer(e.dp, sp_t, q, nullptr);
  dds_delete_qos(q);
  if (e.odom_r < 0 || e.tf_r < 0 || e.sp_w < 0) {
    return std::fprintf(stderr, "cyclone_peer: endpoints\n"), false;
  }
  e.ws = dds_create_waitset(e.dp);
  dds_set_status_mask(e.odom_r, DDS_DATA_AVAILABLE_STATUS);
  dds_set_status_mask(e.tf_r, DDS_DATA_AVAILABLE_STATUS);
  dds_waitset_attach(e.ws, e.odom_r, e.odom_r);
  dds_waitset_attach(e.ws, e.tf_r, e.tf_r);
  return true;
}

// take_all: takes every sample of reader r, calling f(sample, receipt time) for valid ones;
// returns how many.
template <class T, class F>
int take_all(dds_entity_t r, F f) {
  void* samples[16] = {};
  dds_sample_info_t infos[16];
  int count = 0;
  dds_return_t n;
  while ((n = dds_take(r, samples, infos, 16, 16)) > 0) {
    const std::int64_t recv = peer::realtime_ns();
    for (int i = 0; i < n; ++i) {
      if (!infos[i].valid_data) continue;
      ++count;
      f(*static_cast<const T*>(samples[i]), recv);
    }
    dds_return_loan(r, samples, n);
  }
  return count;
}

// ack_set_pose: the writes during the run may all have gone out before the bridge's reader
// matched: once matched, write once more and wait until the bridge's reader acknowledged it.
bool ack_set_pose(const Endpoints& e, const void* sp, double end) {
  dds_publication_matched_status_t st{};
  while (dds_get_publication_matched_status(e.sp_w, &st) == DDS_RETCODE_OK &&
         st.current_count == 0 && peer::monotonic_s() < end) {
    dds_sleepfor(DDS_MSECS(10));
  }
  return st.current_count > 0 && dds_write(e.sp_w, sp) == DDS_RETCODE_OK &&
         dds_wait_for_acks(e.sp_w, DDS_SECS(5)) == DDS_RETCODE_OK;
}

}  // namespace

int main(int argc, char** argv) {
  peer::Args a;
  if (!peer::parse(argc, argv, a)) return peer::usage(argv[0]);
  Endpoints e;
  if (!open(a, e)) return 1;
  geometry_msgs_msg_dds__PoseWithCovarianceStamped_ sp{};
  char odom_frame[] = "odom";
  sp.header.frame_id = odom_frame;
  sp.pose.pose.position.x = a.sp_x;
  sp.pose.pose.position.y = a.sp_y;
  sp.pose.pose.orientation.z = std::sin(a.sp_yaw / 2);
  sp.pose.pose.orientation.w = std::cos(a.sp_yaw / 2);
  for (int i : {0, 7, 35}) sp.pose.covariance[i] = a.sp_var;

  peer::Latency lat;
  lat.skip = a.skip;
  int n_odom = 0, n_tf = 0;
  const double end = peer::monotonic_s() + a.timeout_s;
  peer::Running running{end};
  double next_sp = 0;
  while (running.more(a, n_odom, n_tf)) {
    // 20 ms at most, to publish set_pose on time.
    dds_waitset_wait(e.ws, nullptr, 0, DDS_MSECS(20));
    n_odom += take_all<nav_msgs_msg_dds__Odometry_>(e.odom_r, [&](const auto& o, auto recv) {
      lat.add(o.header.stamp.sec, o.header.stamp.nanosec, recv);
      if (!a.quiet) std::printf("%s\n", odom_line(o, recv).c_str());
    });
    n_tf += take_all<tf2_msgs_msg_dds__TFMessage_>(e.tf_r, [&](const auto& m, auto recv) {
      if (!a.quiet) std::printf("%s\n", tf_line(m, recv).c_str());
    });
    if (a.set_pose && peer::monotonic_s() >= next_sp) {
      dds_write(e.sp_w, &sp);
      next_sp = peer::monotonic_s() + 0.2;
    }
    std::fflush(stdout);
  }
  const bool acked = !a.set_pose || a.idle_s > 0 || ack_set_pose(e, &sp, end);
  const int status = peer::finish(a, lat, n_odom, n_tf, acked);
  dds_delete(e.dp);
  return status;
}
