// Ros2Output: odometryd's ROS 2 output ([ros2], README "ROS 2"): a tick observer that hands each
// tick's pose, velocity and covariances to the ros2 Bridge through a triple buffer, and the
// Bridge's set_pose sink that posts SetPose into the loop's command queue. The loop thread only
// converts and publishes into the buffer (no DDS call, no allocation, no lock); everything DDS
// runs on the Bridge's thread. Private to firmware/.
#pragma once

#include <atomic>
#include <cstdint>
#include <iosfwd>
#include <memory>
#include <string>

#include <nlohmann/json.hpp>

#include "odo/hal/result.hpp"
#include "odo/loop/loop.hpp"
#include "odo/loop/triple_buffer.hpp"
#include "odo/odometry/error_model.hpp"
#include "odo/odometry/kinematics.hpp"
#include "odo/ros2/bridge.hpp"

namespace odo::fw {

class Ros2Output final : public loop::TickObserver {
 public:
  // create: null (and ok) when c is null or not enabled; registers the observer on loop and
  // opens the DDS participant (configure time). k: error model of the twist covariance (the
  // tick's travels and wheelbase come with each snapshot). Errors name the [ros2] field or the
  // DDS call.
  static Result<std::unique_ptr<Ros2Output>> create(const ros2::Config* c, double loop_hz,
                                                    const ErrorModelParams& k,
                                                    loop::OdometryLoop& loop);
  ~Ros2Output() override;
  Ros2Output(const Ros2Output&) = delete;
  Ros2Output& operator=(const Ros2Output&) = delete;

  // on_tick: loop thread; converts the snapshot and publishes it to the bridge's buffer.
  void on_tick(const loop::LoopSnapshot& snap) noexcept override;
  // start: the bridge's thread (before the loop runs), at [ros2] priority unless virtual_time;
  // that part is reported on log like the loop's [realtime] parts, and refused (error) when it
  // fails and `required`. stop: joins the thread, after the loop ran (the newest sample, the
  // final pose, is published before the thread ends).
  Status start(bool virtual_time, bool required, std::ostream& log);
  void stop();
  // describe: one line for the start-up report.
  std::string describe() const;
  // json: the bridge's counters and set_pose commands posted/dropped, for --json.
  nlohmann::json json() const;

 private:
  Ros2Output(const ErrorModelParams& k, loop::OdometryLoop& loop);
  // read: the bridge thread's SampleSource (the buffer's reader side).
  bool read(ros2::OdomSample& s);
  // post: the bridge thread's SetPoseSink.
  void post(const ros2::PoseWithCovarianceFields& p);

  int priority_ = 0;  // [ros2] priority of the publish thread
  ErrorModelParams k_;
  loop::OdometryLoop& loop_;
  loop::TripleBuffer<ros2::OdomSample> samples_;
  std::unique_ptr<ros2::Bridge> bridge_;
  std::string describe_;
  std::atomic<std::uint64_t> set_pose_posted_{0}, set_pose_dropped_{0};
};

}  // namespace odo::fw
