// Bridge in a build without DDS (-DODO_ROS2=OFF): create() says so; the config reader rejects
// [ros2] enabled = true before it gets here (kBuiltWithDds).
#include "odo/ros2/bridge.hpp"

namespace odo::ros2 {

struct Bridge::Impl {};

Bridge::Bridge(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}

Bridge::~Bridge() = default;

Result<std::unique_ptr<Bridge>> Bridge::create(const Config&, double, SampleSource, SetPoseSink) {
  return make_error(Errc::kUnsupported,
                    "ros2: this build has no ROS 2 output (configured with -DODO_ROS2=OFF)");
}

Status Bridge::start(std::function<void()>) {
  return make_error(Errc::kUnsupported, "ros2: no ROS 2 output in this build");
}

void Bridge::stop() {}

BridgeStats Bridge::stats() const {
  return {};
}

}  // namespace odo::ros2
