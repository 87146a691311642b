#include "ros2_output.hpp"

#include <future>
#include <sstream>

#include "odo/drivers/realtime.hpp"
#include "odo/ros2/config.hpp"
#include "realtime_report.hpp"

namespace odo::fw {

Ros2Output::Ros2Output(const ErrorModelParams& k, loop::OdometryLoop& loop) : k_(k), loop_(loop) {}

Ros2Output::~Ros2Output() {
  stop();
}

Result<std::unique_ptr<Ros2Output>> Ros2Output::create(const ros2::Config* c, double loop_hz,
                                                       const ErrorModelParams& k,
                                                       loop::OdometryLoop& loop) {
  if (c == nullptr || !c->enabled) return std::unique_ptr<Ros2Output>();
  std::unique_ptr<Ros2Output> out(new Ros2Output(k, loop));
  Ros2Output* self = out.get();
  auto bridge = ros2::Bridge::create(
      *c, loop_hz, [self](ros2::OdomSample& s) { return self->read(s); },
      [self](const ros2::PoseWithCovarianceFields& p) { self->post(p); });
  if (!bridge) return std::move(bridge).error();
  out->bridge_ = std::move(bridge).value();
  out->priority_ = c->priority;
  if (!loop.add_observer(self)) {
    return make_error(Errc::kBusy, "ros2: the loop has no free observer slot");
  }
  std::ostringstream d;
  d << "DDS domain " << c->domain_id << ", " << ros2::odom_topic(*c)
    << (c->publish_tf ? " + " + ros2::tf_topic() : std::string()) << " at " << c->rate_hz << " Hz, "
    << ros2::set_pose_topic(*c) << " taken; frames " << c->odom_frame << " -> " << c->base_frame;
  out->describe_ = d.str();
  return out;
}

void Ros2Output::on_tick(const loop::LoopSnapshot& snap) noexcept {
  ros2::OdomSample& s = samples_.back();
  s.stamp = snap.stamp;
  s.x = snap.pose.x;
  s.y = snap.pose.y;
  s.theta = snap.pose.theta;
  s.pose_cov = snap.has_cov ? snap.cov : Cov3{};
  s.v = snap.v;
  s.omega = snap.omega;
  // The twist is the tick's difference quotient of what it measured, so its covariance is the
  // error model's for those travels, with the wheelbase and heading source of that tick.
  s.twist_cov = twist_covariance(snap.motion, k_);
  samples_.publish();
}

bool Ros2Output::read(ros2::OdomSample& s) {
  return samples_.latest(s);
}

void Ros2Output::post(const ros2::PoseWithCovarianceFields& p) {
  // The loop takes a set pose as exact (its covariance becomes 0); p.cov is not used.
  if (loop_.post(p.set_pose)) {
    set_pose_posted_.fetch_add(1, std::memory_order_relaxed);
  } else {
    set_pose_dropped_.fetch_add(1, std::memory_order_relaxed);
  }
}

Status Ros2Output::start(bool virtual_time, bool required, std::ostream& log) {
  // Virtual time runs as fast as possible: no thread of it may hog a CPU at real-time priority.
  const int prio = virtual_time ? 0 : priority_;
  std::promise<drivers::RealtimeItem> applied;
  std::future<drivers::RealtimeItem> item = applied.get_future();
  auto started = bridge_->start([prio, &applied] {
    drivers::RealtimeRequest r;
    r.fifo_priority = prio;
    applied.set_value(drivers::apply_realtime(r).front());
  });
  if (!started) return started;
  // The thread reports before it publishes anything: the report is in order with the others.
  drivers::RealtimeItem it = item.get();
  if (prio == 0) it.detail = "off ([ros2] priority = 0): normal time-sharing scheduling";
  std::ostringstream err;  // report_realtime's own line; the daemon prints the error below
  if (report_realtime("ros2 publish thread", it, required, log, err)) return Ok{};
  bridge_->stop();
  return make_error(Errc::kUnsupported, "ros2 publish thread: " + it.what +
                                            " could not be applied and [realtime] required = "
                                            "true: refusing to start (" +
                                            it.detail + ")");
}

void Ros2Output::stop() {
  if (bridge_) bridge_->stop();
}

std::string Ros2Output::describe() const {
  return describe_;
}

nlohmann::json Ros2Output::json() const {
  const ros2::BridgeStats st = bridge_->stats();
  return {{"odom_published", st.odom_published},
          {"tf_published", st.tf_published},
          {"write_errors", st.write_errors},
          {"set_pose_received", st.set_pose_received},
          {"set_pose_rejected", st.set_pose_rejected},
          {"set_pose_posted", set_pose_posted_.load(std::memory_order_relaxed)},
          {"set_pose_dropped", set_pose_dropped_.load(std::memory_order_relaxed)},
          {"write_age_p50", to_seconds(st.write_age_p50_ns)},
          {"write_age_p99", to_seconds(st.write_age_p99_ns)},
          {"write_age_max", to_seconds(st.write_age_max_ns)},
          {"spin_count", st.spin_count},
          {"spin_late", st.spin_late},
          {"due_waits", st.due_waits},
          {"stale_published", st.stale_published},
          {"free_run_published", st.free_run_published},
          {"unpolled_published", st.unpolled_published},
          {"spin_wait_sum", to_seconds(st.spin_wait_sum_ns)}};
}

}  // namespace odo::fw
