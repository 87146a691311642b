// The ROS 2 output over DDS (Cyclone DDS, not ROS): one DDS participant publishing
// nav_msgs/Odometry on rt<ns>/odom and tf2_msgs/TFMessage on rt/tf, and taking
// geometry_msgs/PoseWithCovarianceStamped from rt<ns>/set_pose. Everything DDS runs on the
// bridge's own thread (and Cyclone's): the loop thread only publishes snapshots that the
// SampleSource reads, so a stalled network slows nothing but this thread. No Cyclone type
// appears in this header.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>

#include "odo/hal/result.hpp"
#include "odo/ros2/config.hpp"
#include "odo/ros2/mapping.hpp"

namespace odo::ros2 {

// Called on the bridge thread at every publish tick: fills the newest sample and returns true,
// or false when there is none yet. Must not block (e.g. read a triple buffer's front slot).
using SampleSource = std::function<bool(OdomSample&)>;
// Called on the bridge thread for every valid set_pose received (e.g. post it to the loop).
using SetPoseSink = std::function<void(const PoseWithCovarianceFields&)>;

struct BridgeStats {
  std::uint64_t odom_published = 0;     // rt/odom samples written
  std::uint64_t tf_published = 0;       // rt/tf samples written
  std::uint64_t unchanged_skipped = 0;  // ticks whose sample had been published already
  std::uint64_t write_errors = 0;       // dds_write failures (and stamps out of range)
  std::uint64_t set_pose_received = 0;  // valid set_pose handed to the sink
  std::uint64_t set_pose_rejected = 0;  // set_pose with a wrong frame or invalid values
  // Age of the samples when their rt/odom write returned (monotonic now - sample time) [ns]:
  // the bridge's share of the sample-to-receipt latency.
  std::int64_t write_age_sum_ns = 0;
  std::int64_t write_age_max_ns = 0;
  // Its median and 99th percentile [ns], to 10 us (upper bin edge; 10 ms + 10 us: beyond 10 ms).
  std::int64_t write_age_p50_ns = 0;
  std::int64_t write_age_p99_ns = 0;
  // Sample time of the newest sample written to rt/odom [ns, CLOCK_MONOTONIC]; 0: none yet.
  TimeNs last_published = 0;
  // Early wake-up (Config::spin_us > 0): publishes whose due sample the thread polled for
  // (spin_count), of those the ones already there when it woke, i.e. its wake-up was later than
  // spin_us (spin_late), and the time spent polling [ns] (its CPU cost).
  std::uint64_t spin_count = 0;
  std::uint64_t spin_late = 0;
  std::int64_t spin_wait_sum_ns = 0;
  // Looks at a due tick that was not there yet (the loop woke late: looked again 200 us later),
  // and publishes of an older sample because the due tick had not come half a period after it.
  std::uint64_t due_waits = 0;
  std::uint64_t stale_published = 0;
  // Publishes of the newest sample with no due tick to look for: the first (no phase yet), and
  // each after a wake-up already missed (the thread was not scheduled in time: it skips ticks).
  std::uint64_t free_run_published = 0;
  // Publishes of the due tick without polling for it: spin_us is 0, or the thread woke after
  // due + spin_us, or it had waited for the late tick (due_waits).
  std::uint64_t unpolled_published = 0;
};

class Bridge {
 public:
  // create: validates c (against loop_rate_hz), creates the DDS domain, participant, topics,
  // writers and reader (allocates; configure time). Error names the field or the DDS call.
  static Result<std::unique_ptr<Bridge>> create(const Config& c, double loop_rate_hz,
                                                SampleSource source, SetPoseSink sink);
  ~Bridge();
  Bridge(const Bridge&) = delete;
  Bridge& operator=(const Bridge&) = delete;

  // start: runs the publish thread (rate_hz, phase-locked to the samples' times; with
  // Config::spin_us it wakes that long before each due tick and polls for its sample), which
  // first calls thread_setup (e.g. to give itself a real-time priority); error if running.
  Status start(std::function<void()> thread_setup = {});
  // stop: ends and joins the thread; idempotent. The destructor stops too.
  void stop();
  // stats: counters so far (any thread).
  BridgeStats stats() const;

 private:
  struct Impl;
  explicit Bridge(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

// cyclone_config_xml: the Cyclone DDS configuration the bridge uses for c (interfaces,
// multicast, peers); "" when c leaves everything to Cyclone's defaults.
std::string cyclone_config_xml(const Config& c);

// realtime_minus_monotonic: CLOCK_REALTIME - CLOCK_MONOTONIC [ns], read between two monotonic
// reads (the midpoint; error below half their distance, tens of ns).
TimeNs realtime_minus_monotonic();

}  // namespace odo::ros2
