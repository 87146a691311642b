// Independent ROS 2-style peer on Fast DDS (eProsima, Debian libfastrtps-dev), types generated
// by fastddsgen from ros2/idl/ros2_msgs.idl: receives rt<ns>/odom and rt/tf, prints each message
// (peer_common.hpp's format) or a latency summary, and publishes rt<ns>/set_pose. UDPv4 on
// 127.0.0.1 only, unicast discovery to the well-known ports of participants 0..9, no shared
// memory: nothing leaves the machine.
#include <fastdds/rtps/transport/UDPv4TransportDescriptor.h>
#include <fastrtps/utils/IPLocator.h>
#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>

#include <chrono>
#include <cmath>
#include <memory>
#include <thread>

#include "peer_common.hpp"
#include "ros2_msgs.h"
#include "ros2_msgsPubSubTypes.h"
#include "tsan_suppressions.hpp"

using namespace eprosima::fastdds::dds;
using eprosima::fastdds::rtps::UDPv4TransportDescriptor;
using eprosima::fastrtps::rtps::IPLocator;
using eprosima::fastrtps::rtps::Locator_t;

namespace {

DomainParticipantQos loopback_qos(int domain) {
  DomainParticipantQos q;
  q.transport().use_builtin_transports = false;
  auto udp = std::make_shared<UDPv4TransportDescriptor>();
  udp->interfaceWhiteList.emplace_back("127.0.0.1");
  q.transport().user_transports.push_back(udp);
  for (int pid = 0; pid < 10; ++pid) {
    Locator_t l;
    IPLocator::setIPv4(l, 127, 0, 0, 1);
    l.port = static_cast<uint32_t>(7400 + 250 * domain + 10 + 2 * pid);  // RTPS metatraffic unicast
    q.wire_protocol().builtin.initialPeersList.push_back(l);
  }
  return q;
}

std::string odom_line(const nav_msgs::msg::dds_::Odometry_& o, std::int64_t recv) {
  char b[160];
  std::snprintf(b, sizeof b, "odom %d %u %" PRId64 " %s %s", o.header().stamp().sec(),
                o.header().stamp().nanosec(), recv, o.header().frame_id().c_str(),
                o.child_frame_id().c_str());
  std::string s = b;
  const auto& p = o.pose().pose();
  const double pose[] = {p.position().x(),    p.position().y(),    p.position().z(),
                         p.orientation().x(), p.orientation().y(), p.orientation().z(),
                         p.orientation().w()};
  peer::print_doubles(s, pose, 7);
  peer::print_doubles(s, o.pose().covariance().data(), 36);
  const auto& t = o.twist().twist();
  const double tw[] = {t.linear().x(),  t.linear().y(),  t.linear().z(),
                       t.angular().x(), t.angular().y(), t.angular().z()};
  peer::print_doubles(s, tw, 6);
  peer::print_doubles(s, o.twist().covariance().data(), 36);
  return s;
}

std::string tf_line(const tf2_msgs::msg::dds_::TFMessage_& m, std::int64_t recv) {
  std::string s;
  for (const auto& t : m.transforms()) {
    char b[160];
    std::snprintf(b, sizeof b, "tf %d %u %" PRId64 " %s %s", t.header().stamp().sec(),
                  t.header().stamp().nanosec(), recv, t.header().frame_id().c_str(),
                  t.child_frame_id().c_str());
    s += b;
    const auto& x = t.transform();
    const double v[] = {x.translation().x(), x.translation().y(), x.translation().z(),
                        x.rotation().x(),    x.rotation().y(),    x.rotation().z(),
                        x.rotation().w()};
    peer::print_doubles(s, v, 7);
  }
  return s;
}

// ros_default: ROS 2's default QoS (reliable, volatile, keep last 10) on a reader or writer QoS.
template <class Q>
Q ros_default(Q q) {
  q.reliability().kind = RELIABLE_RELIABILITY_QOS;
  q.durability().kind = VOLATILE_DURABILITY_QOS;
  q.history().kind = KEEP_LAST_HISTORY_QOS;
  q.history().depth = 10;
  return q;
}

struct Endpoints {
  DomainParticipant* dp = nullptr;
  TypeSupport odom_t{new nav_msgs::msg::dds_::Odometry_PubSubType()};
  TypeSupport tf_t{new tf2_msgs::msg::dds_::TFMessage_PubSubType()};
  TypeSupport sp_t{new geometry_msgs::msg::dds_::PoseWithCovarianceStamped_PubSubType()};
  DataReader* odom_r = nullptr;
  DataReader* tf_r = nullptr;
  DataWriter* sp_w = nullptr;
};

// open: loopback participant, the two readers and the set_pose writer; false (message printed)
// on failure.
bool open(const peer::Args& a, Endpoints& e) {
  e.dp = DomainParticipantFactory::get_instance()->create_participant(a.domain,
                                                                      loopback_qos(a.domain));
  if (!e.dp) return std::fprintf(stderr, "fastdds_peer: no participant\n"), false;
  e.odom_t.register_type(e.dp);
  e.tf_t.register_type(e.dp);
  e.sp_t.register_type(e.dp);
  Topic* odom_topic =
      e.dp->create_topic("rt" + a.ns + "/odom", e.odom_t.get_type_name(), TOPIC_QOS_DEFAULT);
  Topic* tf_topic = e.dp->create_topic("rt/tf", e.tf_t.get_type_name(), TOPIC_QOS_DEFAULT);
  Topic* sp_topic =
      e.dp->create_topic("rt" + a.ns + "/set_pose", e.sp_t.get_type_name(), TOPIC_QOS_DEFAULT);
  Subscriber* sub = e.dp->create_subscriber(SUBSCRIBER_QOS_DEFAULT);
  Publisher* pub = e.dp->create_publisher(PUBLISHER_QOS_DEFAULT);
  const DataReaderQos rq = ros_default(DATAREADER_QOS_DEFAULT);
  e.odom_r = sub->create_datareader(odom_topic, rq);
  e.tf_r = sub->create_datareader(tf_topic, rq);
  e.sp_w = pub->create_datawriter(sp_topic, ros_default(DATAWRITER_QOS_DEFAULT));
  if (!e.odom_r || !e.tf_r || !e.sp_w) {
    return std::fprintf(stderr, "fastdds_peer: no endpoints\n"), false;
  }
  return true;
}

// take_all: takes every sample of r, calling f(sample, receipt time) for valid ones; returns
// how many.
template <class T, class F>
int take_all(DataReader* r, F f) {
  T sample;
  SampleInfo info;
  int count = 0;
  while (r->take_next_sample(&sample, &info) == ReturnCode_t::RETCODE_OK) {
    if (!info.valid_data) continue;
    ++count;
    f(sample, peer::realtime_ns());
  }
  return count;
}

// ack_set_pose: the writes during the run may all have gone out before the bridge's reader
// matched: once matched, write once more and wait until the bridge's reader acknowledged it.
bool ack_set_pose(const Endpoints& e, geometry_msgs::msg::dds_::PoseWithCovarianceStamped_& sp,
                  double end) {
  PublicationMatchedStatus st;
  while (e.sp_w->get_publication_matched_status(st) == ReturnCode_t::RETCODE_OK &&
         st.current_count == 0 && peer::monotonic_s() < end) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return st.current_count > 0 && e.sp_w->write(&sp) &&
         e.sp_w->wait_for_acknowledgments(eprosima::fastrtps::Duration_t(5, 0)) ==
             ReturnCode_t::RETCODE_OK;
}

}  // namespace

int main(int argc, char** argv) {
  peer::Args a;
  if (!peer::parse(argc, argv, a)) return peer::usage(argv[0]);
  Endpoints e;
  if (!open(a, e)) return 1;
  geometry_msgs::msg::dds_::PoseWithCovarianceStamped_ sp;
  sp.header().frame_id("odom");
  sp.pose().pose().position().x(a.sp_x);
  sp.pose().pose().position().y(a.sp_y);
  sp.pose().pose().orientation().z(std::sin(a.sp_yaw / 2));
  sp.pose().pose().orientation().w(std::cos(a.sp_yaw / 2));
  for (int i : {0, 7, 35}) sp.pose().covariance()[i] = a.sp_var;

  peer::Latency lat;
  lat.skip = a.skip;
  int n_odom = 0, n_tf = 0;
  const double end = peer::monotonic_s() + a.timeout_s;
  peer::Running running{end};
  double next_sp = 0;
  while (running.more(a, n_odom, n_tf)) {
    e.odom_r->wait_for_unread_message(eprosima::fastrtps::Duration_t(0, 20000000));
    n_odom += take_all<nav_msgs::msg::dds_::Odometry_>(e.odom_r, [&](const auto& o, auto recv) {
      lat.add(o.header().stamp().sec(), o.header().stamp().nanosec(), recv);
      if (!a.quiet) std::printf("%s\n", odom_line(o, recv).c_str());
    });
    n_tf += take_all<tf2_msgs::msg::dds_::TFMessage_>(e.tf_r, [&](const auto& m, auto recv) {
      if (!a.quiet) std::printf("%s\n", tf_line(m, recv).c_str());
    });
    // set_pose again every 0.2 s while running: the first may go out before discovery matched.
    if (a.set_pose && peer::monotonic_s() >= next_sp) {
      e.sp_w->write(&sp);
      next_sp = peer::monotonic_s() + 0.2;
    }
    std::fflush(stdout);
  }
  const bool acked = !a.set_pose || a.idle_s > 0 || ack_set_pose(e, sp, end);
  const int status = peer::finish(a, lat, n_odom, n_tf, acked);
  e.dp->delete_contained_entities();
  DomainParticipantFactory::get_instance()->delete_participant(e.dp);
  return status;
}
