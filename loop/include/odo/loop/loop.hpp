// OdometryLoop: the fixed-rate loop. One tick: sleep to an absolute deadline, apply the commands
// posted since the last tick, read the encoders (and the yaw-rate gyro, when there is one), take
// wrap-aware deltas, fuse the gyro's heading over the intervals where it and odometry disagree
// (gyrodometry), integrate the pose and its covariance, update timing statistics, hand the
// snapshot to the (read-only) observers.
// The same code runs against real drivers and against sim_hal; only the wiring differs.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <memory>
#include <optional>

#include "odo/calibration/store.hpp"
#include "odo/hal/clock.hpp"
#include "odo/hal/encoder.hpp"
#include "odo/hal/gyro.hpp"
#include "odo/hal/result.hpp"
#include "odo/loop/command.hpp"
#include "odo/loop/latency_histogram.hpp"
#include "odo/loop/state_record.hpp"
#include "odo/loop/triple_buffer.hpp"
#include "odo/odometry/count_delta.hpp"
#include "odo/odometry/error_model.hpp"
#include "odo/odometry/gyrodometry.hpp"
#include "odo/odometry/kinematics.hpp"
#include "odo/odometry/pose.hpp"

namespace odo::loop {

// Timing figures of the loop; updated every tick without allocation.
struct LoopStats {
  std::uint64_t ticks = 0;
  std::uint64_t missed_deadlines = 0;  // periods skipped because a tick overran
  TimeNs wakeup_latency_last = 0;      // wake-up time minus deadline [ns]
  TimeNs wakeup_latency_max = 0;       // [ns]
  TimeNs wakeup_latency_sum = 0;       // [ns], for the mean
  TimeNs compute_max = 0;              // tick body duration, worst [ns]
  // Histogram summaries (min, mean, p99, p99.9, max [ns]) of the wake-up latency and of the
  // compute time; refreshed every kSummaryTicks ticks and when run() returns.
  TimingSummary wakeup_latency;
  TimingSummary compute_time;
};

// The gyro and its fusion as of one tick (all zero when the loop runs without a gyro).
struct LoopGyroStatus {
  bool enabled = false;            // a yaw-rate source is wired
  std::uint32_t gyro_flags = 0;    // GyroFlag bits of the last sample
  std::uint32_t fusion_flags = 0;  // FusionFlag bits of the last tick
  double rate_z = 0.0;             // last sample's mean rate [rad/s]
  double bias = 0.0;               // the fusion's bias estimate [rad/s]
  bool bias_valid = false;         // learnt at standstill (detection is on)
  double scale = 1.0;              // the fusion's scale-factor estimate
  FusionCounters fusion;           // bumps/slips detected, gyro-heading ticks, faults
  GyroCounters gyro;               // the source's own counters
};

// What one tick produced; observers and the status thread see this.
struct LoopSnapshot {
  std::uint64_t tick = 0;
  TimeNs stamp = 0;      // sample time of the encoder reading [ns]
  TimeNs loop_time = 0;  // time since the loop started [ns]
  Pose2 pose;            // cumulative heading
  double v = 0.0;        // [m/s]
  double omega = 0.0;    // yaw rate [rad/s], CCW positive
  // What this tick measured (wheel travels, their interval, the wheelbase in use, the gyro's
  // heading variance on a fused tick): consumers derive from it, never invert (v, omega).
  TickMotion motion;
  double distance = 0.0;            // path length of the centre point [m]
  std::uint32_t encoder_flags = 0;  // EncoderFlag bits of the last sample
  EncoderCounters encoder_counters;
  LoopStats stats;
  // Pose covariance of (x, y, theta), row-major [m^2, m rad, rad^2]; valid when has_cov.
  std::array<double, 9> cov{};
  bool has_cov = false;
  // The calibration store's status of the kinematics in use (kUncalibrated: nominal values).
  calib::StoreStatus calibration_state = calib::StoreStatus::kUncalibrated;
  LoopGyroStatus gyro;
};

// TickObserver: called on the loop thread after every tick with that tick's snapshot; reads it,
// must not block or allocate. An observer that wants to change the loop posts a Command. Its
// stats are those up to this tick's wake-up (compute time and missed deadlines: up to the
// previous tick).
class TickObserver {
 public:
  virtual ~TickObserver() = default;
  virtual void on_tick(const LoopSnapshot& snap) noexcept = 0;
};

// kLoopRateLimit: the allowed loop rate [Hz] (checked by create and by the config reader).
inline constexpr Limit kLoopRateLimit{50.0, 2000.0};

struct LoopConfig {
  double rate_hz = 100.0;        // [Hz], kLoopRateLimit
  ErrorModelParams error_model;  // Chong-Kleeman k_L, k_R for the pose covariance
  // The store's status of the kinematics the loop starts with (snapshot calibration_state).
  calib::StoreStatus calibration = calib::StoreStatus::kUncalibrated;
  // Gyrodometry, used when create() is given a yaw-rate source; its tick and heading_quantum
  // are set by create() from the loop rate and the kinematics.
  GyrodometryParams gyrodometry;
  // Estimate the gyro's scale factor from turns while the kinematics are calibrated.
  bool gyro_scale_estimation = true;
  // [ns] start(): while the reference reading is stale or failed (a CAN controller that has not
  // sent yet), read again every millisecond for at most this long; 0: take the first reading.
  // A wheel still stale then is referenced at its first fresh reading (no jump from its 0).
  TimeNs start_wait = 0;
};

// SlipVariance: the extra variances [m^2] of the sides' travels on one tick of a within-side
// slip interval (slip_travel_variance).
struct SlipVariance {
  double left = 0.0;
  double right = 0.0;
};

class OdometryLoop {
 public:
  static constexpr std::size_t kMaxObservers = 8;
  static constexpr std::uint64_t kSummaryTicks = 256;  // power of two

  // create: validates the rate, the encoder's counter width and, with a gyro, the fusion's
  // parameters (heap-allocated once, at configure time: the loop holds atomics and is neither
  // copied nor moved). gyro: optional yaw-rate source, read every tick; null: odometry alone.
  static Result<std::unique_ptr<OdometryLoop>> create(const LoopConfig& cfg, const Kinematics& k,
                                                      EncoderSource& encoder, Clock& clock,
                                                      YawRateSource* gyro = nullptr);

  // add_observer: registers a per-tick observer (configure time only); false when full.
  bool add_observer(TickObserver* o) noexcept;
  // start: latches the reference counts and sets the first deadline one period from now.
  void start() noexcept;
  // resume_from: configure time; the next start() continues from `rec` when decide_resume()
  // allows (the gap's counts integrated as one step) and starts fresh otherwise.
  void resume_from(const StateRecord& rec, const ResumeContext& ctx) noexcept;
  // resume_decision: what start() decided (kNoRecord when resume_from was not called); valid
  // on other threads once resume_decided() is true.
  const ResumeDecision& resume_decision() const noexcept { return resume_; }
  bool resume_decided() const noexcept { return resume_decided_.load(std::memory_order_acquire); }
  // Reference reading of the last integrated sample: raw counts and their sample time [ns]
  // (loop thread, e.g. an observer persisting the state).
  std::int64_t last_left() const noexcept { return prev_left_; }
  std::int64_t last_right() const noexcept { return prev_right_; }
  TimeNs last_stamp() const noexcept { return prev_stamp_; }
  // The counters' own values at the last integrated sample (last_left/right plus the counts of
  // the jumps the backend rejected, wrap rule): what a restarted process will read.
  std::int64_t last_counter_left() const noexcept {
    return counter_value(prev_left_, prev_rejected_left_, bits_);
  }
  std::int64_t last_counter_right() const noexcept {
    return counter_value(prev_right_, prev_rejected_right_, bits_);
  }
  int counter_bits() const noexcept { return bits_; }
  calib::StoreStatus calibration() const noexcept { return calibration_; }
  // tick: runs one period of the loop (sleeps until the deadline first).
  void tick() noexcept;
  // run: ticks until `stop` is set or `duration` [ns] of loop time passed (duration <= 0: no
  // limit). Calls start() first.
  void run(TimeNs duration, const std::atomic<bool>& stop) noexcept;

  // post: any thread (observers included); the command is applied at the top of the next tick.
  // False when the queue is full (CommandQueue::kCapacity commands not yet taken).
  bool post(const Command& c) noexcept { return commands_.post(c); }
  // commands: the inbound queue, for producers that are handed the queue rather than the loop.
  CommandQueue& commands() noexcept { return commands_; }
  // commands_applied: commands applied so far, readable from any thread.
  std::uint64_t commands_applied() const noexcept {
    return commands_applied_.load(std::memory_order_acquire);
  }

  const Odometry& odometry() const noexcept { return odom_; }
  // fusion: the gyrodometry fusion, null without a gyro (loop thread, or after run()).
  const Gyrodometry* fusion() const noexcept { return fusion_ ? &*fusion_ : nullptr; }
  const LoopStats& stats() const noexcept { return stats_; }
  // Full histograms (loop thread, or after run() returned).
  const LatencyHistogram& wakeup_histogram() const noexcept { return wakeup_hist_; }
  const LatencyHistogram& compute_histogram() const noexcept { return compute_hist_; }
  // heartbeat: ticks so far, readable from any thread (the watchdog proves the loop is alive).
  std::uint64_t heartbeat() const noexcept { return heartbeat_.load(std::memory_order_relaxed); }
  // snapshot: the newest snapshot, for the loop's own thread (or after run() returned).
  const LoopSnapshot& snapshot() const noexcept { return published_.newest(); }
  TimeNs period() const noexcept { return period_; }
  // snapshots: the newest snapshot for another thread (status printer, supervisor).
  TripleBuffer<LoopSnapshot>& snapshots() noexcept { return published_; }

 private:
  OdometryLoop(TimeNs period, const LoopConfig& cfg, const Kinematics& k, EncoderSource& enc,
               Clock& clock);

  // The steps of tick(), in order.
  // wait_for_deadline: sleeps to the deadline; the wake-up time [ns].
  TimeNs wait_for_deadline() noexcept;
  // integrate: the encoder sample's motion since the previous good one (and the gyro's, fused).
  void integrate(const EncoderSample& s) noexcept;
  // take_reference: a wheel fresh for the first time since start() starts counting here.
  void take_reference(const EncoderSample& s) noexcept;
  // integrate_fused: one interval of count deltas dl, dr over dt [s] with the gyro's reading up to
  // `stamp` [ns].
  // slip: the extra travel variances of a tick inside a within-side slip interval (null: none).
  void integrate_fused(std::int64_t dl, std::int64_t dr, double dt, TimeNs stamp,
                       const SlipVariance* slip) noexcept;
  // integrate_slip: integrate() of a sample flagged kEncoderSlipLeft/Right (several encoders per
  // side): the sides' extra travel variances grow the covariance and, with a gyro, force its
  // heading (out of line: the one-encoder path never comes here).
  void integrate_slip(const EncoderSample& s, std::int64_t dl, std::int64_t dr, double dt) noexcept;
  // record_wakeup: the wake-up latency [ns] into the statistics.
  void record_wakeup(TimeNs latency) noexcept;
  // fill_snapshot: this tick's snapshot in the back slot (every field that changes).
  LoopSnapshot& fill_snapshot(const EncoderSample& s, TimeNs woke) noexcept;
  // fill_gyro_status: the gyro and fusion part of the snapshot (its status, the motion's gyro
  // fields).
  void fill_gyro_status(LoopSnapshot& snap) const noexcept;
  // record_compute: the tick's compute time from `woke` to `done` [ns] into the statistics.
  void record_compute(LoopSnapshot& snap, TimeNs latency, TimeNs woke, TimeNs done) noexcept;
  // schedule_next: the next deadline; after an overrun the missed periods are skipped.
  void schedule_next(LoopSnapshot& snap, TimeNs done) noexcept;
  // scale_estimation_wanted: whether the fusion should estimate the gyro's scale now.
  bool scale_estimation_wanted() const noexcept {
    return gyro_scale_estimation_ && calibration_ == calib::StoreStatus::kOk;
  }

  TimeNs period_;
  Odometry odom_;
  calib::StoreStatus calibration_;
  EncoderSource* enc_;
  Clock* clock_;
  int bits_;
  TimeNs start_wait_;  // [ns] LoopConfig::start_wait
  YawRateSource* gyro_ = nullptr;
  std::optional<Gyrodometry> fusion_;  // engaged when gyro_ is set
  bool gyro_scale_estimation_ = true;
  // The last tick's fusion input; its gyro field is the gyro's last reading (for the snapshot),
  // read into it directly (a 64-byte GyroSample copied once a tick, not twice).
  FusionInput fused_in_;
  std::uint32_t last_fusion_flags_ = 0;
  double last_dt_ = 0.0;           // [s] interval of the last integrated tick (TickMotion::dt)
  double last_var_heading_ = 0.0;  // [rad^2] its fused heading increment's variance
  // Within-side slip intervals (integrate_slip): each side's spread so far [m] and the tick
  // (stats_.ticks before it) and flags of the last slip tick, to tell an interval's first tick.
  double slip_spread_left_ = 0.0, slip_spread_right_ = 0.0;
  std::uint64_t slip_tick_ = ~std::uint64_t{0};
  std::uint32_t slip_flags_ = 0;
  std::array<TickObserver*, kMaxObservers> observers_{};
  std::size_t n_observers_ = 0;

  TimeNs start_ = 0;
  TimeNs deadline_ = 0;
  std::int64_t prev_left_ = 0;
  std::int64_t prev_right_ = 0;
  std::int64_t prev_rejected_left_ = 0;  // the last integrated sample's left/right_rejected
  std::int64_t prev_rejected_right_ = 0;
  // Stale flags of wheels that have not had a fresh reading since start(): their reference
  // count is taken from their first fresh reading, not integrated from the stale one.
  std::uint32_t unreferenced_ = 0;
  TimeNs prev_stamp_ = 0;
  LoopStats stats_;
  LatencyHistogram wakeup_hist_;
  LatencyHistogram compute_hist_;
  std::atomic<std::uint64_t> heartbeat_{0};
  // Each tick builds its snapshot in the triple buffer's back slot and publishes it in place.
  TripleBuffer<LoopSnapshot> published_;

  // copy_newest: the back slot filled with the newest snapshot and the current statistics, to be
  // published (start-up and end of run only: it copies the whole snapshot).
  LoopSnapshot& copy_newest() noexcept;

  // apply_commands: everything posted since the last tick, oldest first (top of a tick).
  void apply_commands() noexcept;

  CommandQueue commands_;
  std::atomic<std::uint64_t> commands_applied_{0};

  // resume (issue 17): the record offered at configure time and start()'s decision.
  // apply_resume: decides on the reference reading `s`; on resume restores the record's state
  // and integrates the gap as one step.
  void apply_resume(const EncoderSample& s) noexcept;
  // restore_gyro: the record's gyro calibration into the fusion when decide_resume matched it.
  void restore_gyro() noexcept;
  StateRecord resume_rec_;
  ResumeContext resume_ctx_;
  bool resume_offered_ = false;
  ResumeDecision resume_;
  std::atomic<bool> resume_decided_{false};
};

// fill_state_record: the loop's state after its last tick into `r` (pose, covariance, distance,
// reference counts and their sample time, counter width, kinematics, calibration status); the
// identity fields (sequence, boot id, clock epoch, backend, calibration sequence) are the
// caller's. Loop thread (an observer) or after run() returned; no allocation.
void fill_state_record(const OdometryLoop& loop, StateRecord& r) noexcept;

}  // namespace odo::loop
