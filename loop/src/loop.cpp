#include "odo/loop/loop.hpp"

#include <cmath>
#include <string>

#include "odo/hal/field_range.hpp"
#include "odo/odometry/count_delta.hpp"

namespace odo::loop {

Result<std::unique_ptr<OdometryLoop>> OdometryLoop::create(const LoopConfig& cfg,
                                                           const Kinematics& k,
                                                           EncoderSource& encoder, Clock& clock,
                                                           YawRateSource* gyro) {
  if (!kLoopRateLimit.contains(cfg.rate_hz)) {
    const Limit l = kLoopRateLimit;
    return range_error({"loop.rate_hz", cfg.rate_hz, l.lo, l.hi, "Hz", false});
  }
  if (auto s = check_counter_bits(encoder.counter_bits()); !s) return std::move(s).error();
  if (auto s = check_error_model(cfg.error_model); !s) {
    return make_error(Errc::kInvalidArgument, "error_model." + s.error().message);
  }
  const auto period = static_cast<TimeNs>(std::llround(1e9 / cfg.rate_hz));
  std::optional<Gyrodometry> fusion;
  if (gyro != nullptr) {
    GyrodometryParams p = cfg.gyrodometry;
    // Odometry's own noise is the one the covariance uses: the fusion's threshold and the pose's
    // uncertainty read the same k_L, k_R.
    p.odometry_noise = cfg.error_model;
    p.tick = to_seconds(period);
    // One count on each wheel: the resolution of odometry's heading over any window.
    p.heading_quantum = (k.metres_per_count_left() + k.metres_per_count_right()) / k.wheelbase();
    auto f = Gyrodometry::create(p);
    if (!f) return std::move(f).error();
    fusion.emplace(std::move(f).value());
  }
  std::unique_ptr<OdometryLoop> loop(new OdometryLoop(period, cfg, k, encoder, clock));
  loop->gyro_ = gyro;
  loop->fusion_ = std::move(fusion);
  loop->gyro_scale_estimation_ = cfg.gyro_scale_estimation;
  if (loop->fusion_) loop->fusion_->set_scale_estimation(loop->scale_estimation_wanted());
  return loop;
}

OdometryLoop::OdometryLoop(TimeNs period, const LoopConfig& cfg, const Kinematics& k,
                           EncoderSource& enc, Clock& clock)
    : period_(period),
      odom_(k, cfg.error_model),
      calibration_(cfg.calibration),
      enc_(&enc),
      clock_(&clock),
      bits_(enc.counter_bits()),
      start_wait_(cfg.start_wait) {}

bool OdometryLoop::add_observer(TickObserver* o) noexcept {
  if (n_observers_ >= kMaxObservers) return false;
  observers_[n_observers_++] = o;
  return true;
}

void OdometryLoop::start() noexcept {
  EncoderSample s = enc_->read(clock_->now());
  // A reference reading before the encoder is ready would make a resume impossible
  // (encoder-not-ready) and the first real counts relative to nothing: wait for it, bounded.
  constexpr std::uint32_t kNotReady = kEncoderReadError | kEncoderStaleLeft | kEncoderStaleRight;
  for (const TimeNs until = clock_->now() + start_wait_;
       (s.flags & kNotReady) != 0 && clock_->now() < until;) {
    clock_->sleep_until(clock_->now() + kNsPerSecond / 1000);  // 1 ms
    s = enc_->read(clock_->now());
  }
  if (resume_offered_) apply_resume(s);
  // The gyro's samples up to now belong to no interval of the encoders: dropped.
  if (gyro_ != nullptr) fused_in_.gyro = gyro_->read(clock_->now());
  prev_left_ = s.left;
  prev_right_ = s.right;
  prev_rejected_left_ = s.left_rejected;
  prev_rejected_right_ = s.right_rejected;
  prev_stamp_ = s.stamp;
  unreferenced_ = s.flags & (kEncoderStaleLeft | kEncoderStaleRight);
  // Loop time starts once the reference counts are latched, however long that read took; the
  // first deadline is one period later.
  start_ = clock_->now();
  deadline_ = start_ + period_;
  // The reference reading's flags are the snapshot until the first tick.
  LoopSnapshot& b = copy_newest();
  b.encoder_flags = s.flags;
  b.encoder_counters = s.counters;
  b.calibration_state = calibration_;
  b.pose = odom_.pose();
  b.distance = odom_.distance();
  b.cov = odom_.covariance();
  fill_gyro_status(b);
  published_.publish();
  resume_decided_.store(true, std::memory_order_release);
}

void OdometryLoop::resume_from(const StateRecord& rec, const ResumeContext& ctx) noexcept {
  resume_rec_ = rec;
  resume_ctx_ = ctx;
  resume_offered_ = true;
}

void OdometryLoop::apply_resume(const EncoderSample& s) noexcept {
  resume_ctx_.now = clock_->now();
  resume_ = decide_resume(resume_rec_, resume_ctx_, s);
  restore_gyro();
  if (!resume_.resumed()) return;
  odom_.restore(resume_rec_.pose, resume_rec_.cov, resume_rec_.distance);
  // The downtime is one long step, as after an overrun: its counts are integrated exactly
  // once (the arc of a constant-curvature gap is exact) and the covariance grows for it.
  odom_.advance(resume_.dl, resume_.dr, to_seconds(resume_.gap));
  resume_.pose = odom_.pose();
}

void OdometryLoop::restore_gyro() noexcept {
  // The same gyro (its id says so) in the same boot: its bias has drifted only for the gap, as
  // it drifts on any drive without a standstill, so detection goes on at once, with the pose or
  // from a fresh one (GPIO quadrature never resumes the pose).
  if (!fusion_ || !resume_.gyro_matches) return;
  GyroCalibration c = resume_rec_.gyro;
  // The scale was learnt against odometry's heading with the record's kinematics and
  // calibration: only with the pose, which resumes only when those are the same.
  if (!resume_.resumed()) c.scale_valid = false;
  resume_.gyro_restored = fusion_->restore(c);
  resume_.gyro = fusion_->calibration();  // told by other threads: a copy, not the fusion's
}

LoopSnapshot& OdometryLoop::copy_newest() noexcept {
  LoopSnapshot& b = published_.back();
  b = published_.newest();
  b.stats = stats_;
  return b;
}

void OdometryLoop::apply_commands() noexcept {
  const std::size_t n = commands_.drain([this](const Command& c) {
    if (const auto* p = std::get_if<SetPose>(&c)) {
      odom_.reset(p->pose);  // and its covariance: a set pose is exact
      // The window's increments led to the old pose: a flagged interval must not replace them.
      if (fusion_) fusion_->reset();
    } else if (const auto* k = std::get_if<SetKinematics>(&c)) {
      odom_.set_kinematics(k->kinematics);
      calibration_ = k->calibration;
      if (fusion_) fusion_->set_scale_estimation(scale_estimation_wanted());
    }
  });
  commands_applied_.fetch_add(n, std::memory_order_release);
}

void OdometryLoop::tick() noexcept {
  const TimeNs woke = wait_for_deadline();
  const TimeNs latency = woke - deadline_;
  // Commands take effect before this tick's motion is added; nearly every tick finds none.
  if (!commands_.empty()) apply_commands();
  const EncoderSample s = enc_->read(woke);
  integrate(s);
  record_wakeup(latency);
  LoopSnapshot& snap = fill_snapshot(s, woke);
  for (std::size_t i = 0; i < n_observers_; ++i) observers_[i]->on_tick(snap);
  const TimeNs done = clock_->now();
  record_compute(snap, latency, woke, done);
  heartbeat_.store(stats_.ticks, std::memory_order_relaxed);
  schedule_next(snap, done);
  published_.publish();
}

TimeNs OdometryLoop::wait_for_deadline() noexcept {
  clock_->sleep_until(deadline_);
  return clock_->now();
}

// integrate, integrate_fused, fill_snapshot and record_compute run once a tick and are called from
// tick() only: inlined into it, so that a tick pays no calls (and register saves) for them
// (-43 instructions a tick with the gyro, tools/callgrind_tick.sh).
[[gnu::always_inline]] inline void OdometryLoop::integrate(const EncoderSample& s) noexcept {
  // After a failed encoder read the gyro is not read either: its samples keep accumulating and
  // the next read averages them over the same (longer) interval as the next good counts.
  if ((s.flags & kEncoderReadError) != 0) return;
  if (unreferenced_ != 0) take_reference(s);
  // Counts are cumulative, so a late tick simply integrates a longer interval: nothing is lost.
  const std::int64_t dl = wrap_delta(prev_left_, s.left, bits_);
  const std::int64_t dr = wrap_delta(prev_right_, s.right, bits_);
  const double dt = to_seconds(s.stamp - prev_stamp_);
  last_dt_ = dt;
  if ((s.flags & (kEncoderSlipLeft | kEncoderSlipRight)) != 0) [[unlikely]] {
    integrate_slip(s, dl, dr, dt);
  } else if (fusion_) {
    integrate_fused(dl, dr, dt, s.stamp, nullptr);
  } else {
    odom_.advance(dl, dr, dt);
  }
  prev_left_ = s.left;
  prev_right_ = s.right;
  prev_rejected_left_ = s.left_rejected;
  prev_rejected_right_ = s.right_rejected;
  prev_stamp_ = s.stamp;
}

void OdometryLoop::take_reference(const EncoderSample& s) noexcept {
  // A count read while the wheel was stale since start is no reference (a CAN controller that
  // had not sent yet reads 0): the first fresh count is, so the wheel's motion starts there.
  if ((unreferenced_ & kEncoderStaleLeft) != 0 && (s.flags & kEncoderStaleLeft) == 0) {
    prev_left_ = s.left;
    unreferenced_ &= ~static_cast<std::uint32_t>(kEncoderStaleLeft);
  }
  if ((unreferenced_ & kEncoderStaleRight) != 0 && (s.flags & kEncoderStaleRight) == 0) {
    prev_right_ = s.right;
    unreferenced_ &= ~static_cast<std::uint32_t>(kEncoderStaleRight);
  }
}

[[gnu::always_inline]] inline void OdometryLoop::integrate_fused(
    std::int64_t dl, std::int64_t dr, double dt, TimeNs stamp, const SlipVariance* slip) noexcept {
  FusionInput& in = fused_in_;
  gyro_->read_into(stamp, in.gyro);
  const Kinematics& k = odom_.kinematics();
  in.dt = dt;
  in.d_left = static_cast<double>(dl) * k.metres_per_count_left();
  in.d_right = static_cast<double>(dr) * k.metres_per_count_right();
  in.wheelbase = k.wheelbase();
  in.slip = slip != nullptr;
  const FusedTick f = fusion_->step(in);
  last_fusion_flags_ = f.flags;
  last_var_heading_ = f.var_heading;
  if (slip != nullptr) {
    odom_.advance_slip(in.d_left, in.d_right, dt, f.dtheta, f.ds, (f.flags & kFusionGyroUsed) != 0,
                       f.var_heading, slip->left, slip->right);
  } else if ((f.flags & kFusionGyroUsed) == 0) {
    // Odometry's own increment and no travel correction: the plain path, which computes exactly
    // what advance_fused would for it (Odometry::update_fused's contract), at the plain cost,
    // from the travels already converted for the fusion (the counts are converted once).
    odom_.advance_travel(in.d_left, in.d_right, dt);
  } else {
    odom_.advance_fused(in.d_left, in.d_right, dt, f.dtheta, f.ds, true, f.var_heading);
  }
}

[[gnu::noinline]] void OdometryLoop::integrate_slip(const EncoderSample& s, std::int64_t dl,
                                                    std::int64_t dr, double dt) noexcept {
  // A side's interval starts on the first tick it is flagged (the tick before was no slip tick
  // of that side): its spread so far restarts from the window's (SideStep::spread).
  const std::uint32_t before = slip_tick_ + 1 == stats_.ticks ? slip_flags_ : 0u;
  if ((before & kEncoderSlipLeft) == 0) slip_spread_left_ = 0.0;
  if ((before & kEncoderSlipRight) == 0) slip_spread_right_ = 0.0;
  slip_tick_ = stats_.ticks;
  slip_flags_ = s.flags;
  const Kinematics& k = odom_.kinematics();
  SlipVariance v;
  v.left = slip_travel_variance(slip_spread_left_,
                                static_cast<double>(s.spread_left) * k.metres_per_count_left());
  v.right = slip_travel_variance(slip_spread_right_,
                                 static_cast<double>(s.spread_right) * k.metres_per_count_right());
  if (fusion_) {
    integrate_fused(dl, dr, dt, s.stamp, &v);
    return;
  }
  const double d_l = static_cast<double>(dl) * k.metres_per_count_left();
  const double d_r = static_cast<double>(dr) * k.metres_per_count_right();
  odom_.advance_slip(d_l, d_r, dt, (d_r - d_l) / k.wheelbase(), 0.0, false, 0.0, v.left, v.right);
}

void OdometryLoop::record_wakeup(TimeNs latency) noexcept {
  ++stats_.ticks;
  stats_.wakeup_latency_last = latency;
  stats_.wakeup_latency_sum += latency;
  if (latency > stats_.wakeup_latency_max) stats_.wakeup_latency_max = latency;
}

[[gnu::always_inline]] inline LoopSnapshot& OdometryLoop::fill_snapshot(const EncoderSample& s,
                                                                        TimeNs woke) noexcept {
  // Built where the status thread will read it: the back slot of the triple buffer. That slot
  // holds a snapshot two or three ticks old, so every field that changes is written here or by
  // the observers on every tick.
  LoopSnapshot& snap = published_.back();
  snap.tick = stats_.ticks;
  snap.stamp = s.stamp;
  snap.loop_time = woke - start_;
  snap.pose = odom_.pose();
  snap.v = odom_.linear_velocity();
  snap.omega = odom_.angular_velocity();
  // What the tick measured, field by field (the gyro's part in fill_gyro_status, with a fusion).
  snap.motion.d_left = odom_.last_d_left();
  snap.motion.d_right = odom_.last_d_right();
  snap.motion.dt = last_dt_;
  snap.motion.wheelbase = odom_.kinematics().wheelbase();
  snap.distance = odom_.distance();
  snap.cov = odom_.covariance();
  snap.has_cov = true;
  snap.calibration_state = calibration_;
  snap.encoder_flags = s.flags;
  snap.encoder_counters = s.counters;
  fill_gyro_status(snap);
  // Observers see the statistics up to this tick's wake-up; the fields that change after them
  // are patched in below, so the published snapshot carries the statistics of the whole tick.
  snap.stats = stats_;
  return snap;
}

void OdometryLoop::fill_gyro_status(LoopSnapshot& snap) const noexcept {
  if (!fusion_) return;  // stays all zero: the default of every slot
  snap.motion.gyro_heading = (last_fusion_flags_ & kFusionGyroUsed) != 0;
  snap.motion.gyro_var_heading = last_var_heading_;
  LoopGyroStatus& g = snap.gyro;
  g.enabled = true;
  g.gyro_flags = fused_in_.gyro.flags;
  g.fusion_flags = last_fusion_flags_;
  g.rate_z = fused_in_.gyro.rate_z;
  g.bias = fusion_->bias();
  g.bias_valid = fusion_->bias_valid();
  g.scale = fusion_->scale();
  g.fusion = fusion_->counters();
  g.gyro = fused_in_.gyro.counters;
}

[[gnu::always_inline]] inline void OdometryLoop::record_compute(LoopSnapshot& snap, TimeNs latency,
                                                                TimeNs woke, TimeNs done) noexcept {
  const TimeNs compute = done - woke;
  if (compute > stats_.compute_max) stats_.compute_max = compute;
  wakeup_hist_.record(latency);
  compute_hist_.record(compute);
  if ((stats_.ticks & (kSummaryTicks - 1)) == 0) {
    stats_.wakeup_latency = wakeup_hist_.summary();
    stats_.compute_time = compute_hist_.summary();
    snap.stats.wakeup_latency = stats_.wakeup_latency;
    snap.stats.compute_time = stats_.compute_time;
  }
  snap.stats.compute_max = stats_.compute_max;
}

void OdometryLoop::schedule_next(LoopSnapshot& snap, TimeNs done) noexcept {
  deadline_ += period_;
  if (done >= deadline_) {
    const TimeNs behind = done - deadline_;
    const TimeNs skipped = behind / period_ + 1;
    deadline_ += skipped * period_;
    stats_.missed_deadlines += static_cast<std::uint64_t>(skipped);
  }
  snap.stats.missed_deadlines = stats_.missed_deadlines;
}

void OdometryLoop::run(TimeNs duration, const std::atomic<bool>& stop) noexcept {
  start();
  while (!stop.load(std::memory_order_relaxed)) {
    if (duration > 0 && deadline_ - start_ > duration) break;
    tick();
  }
  stats_.wakeup_latency = wakeup_hist_.summary();
  stats_.compute_time = compute_hist_.summary();
  // Ticks still merged into a covariance group (error_model.covariance_ticks > 1) belong in the
  // final pose's covariance: the last snapshot is what a stop saves and reports.
  odom_.flush_covariance();
  copy_newest().cov = odom_.covariance();
  published_.publish();
}

}  // namespace odo::loop
