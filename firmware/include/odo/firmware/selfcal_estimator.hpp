// The self-calibration estimator of odometryd (issue 18): a thread beside the loop that takes
// the loop's recorded count segments (RecordingEncoder -> SegmentRing) and the absolute fixes
// (CAN FixPose + FixSigma through a FixRing from the loop thread, or submit() from any other
// thread), runs calib::fit_fixes on a window of fixes, and applies a candidate only when
// fit_fixes accepts it (every sigma below its bound and a better held-out prediction than the
// calibration in use): written through the A/B store with its provenance, then posted to the
// loop as SetKinematics. A rejected or failed candidate changes nothing.
//
// Fixes go to this thread directly, not through the loop's CommandQueue: a fix changes no
// loop state (the estimator is its only consumer), and its time stamp, not its arrival, places
// it in the recorded counts (build_track splits the segment that straddles the fix time), so
// the loop has nothing to add. The recorded segments of the window are the pose history: a
// late fix is matched to the counts up to its own moment.
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <ostream>
#include <string>
#include <thread>
#include <vector>

#include "odo/calibration/fix_window.hpp"
#include "odo/calibration/selfcal.hpp"
#include "odo/calibration/store.hpp"
#include "odo/firmware/config.hpp"
#include "odo/loop/command.hpp"
#include "odo/loop/recording_encoder.hpp"
#include "odo/odometry/kinematics.hpp"

namespace odo::fw {

using loop::FixRing;

struct SelfCalCounters {
  std::uint64_t fixes_received = 0;
  std::uint64_t fixes_dropped = 0;   // not after the previous fix, or older than the record
  std::uint64_t fixes_rejected = 0;  // outliers flagged by a fit (each fix counted once)
  std::uint64_t fits = 0;
  std::uint64_t fit_errors = 0;
  std::uint64_t accepted = 0;  // candidates applied
  std::uint64_t written = 0;   // records saved in the store
  std::uint64_t store_errors = 0;
  std::uint64_t segments = 0;                // taken from the loop's ring
  std::optional<calib::SelfCalResult> last;  // the newest fit
};

struct SelfCalSetup {
  SelfCalSection cfg;
  KinematicParams nominal;        // the config's robot
  KinematicParams in_use;         // nominal with the stored calibration applied
  ErrorModelParams noise;         // wheel noise for the residual covariance
  TimeNs ripe_delay = 0;          // a fix is taken once the record reaches fix time + this [ns]
  std::size_t fix_capacity = 64;  // FixRing size
  // Who speaks in the log lines, and what "stored" means there (odomctl selfcal simulate runs
  // the estimator on a simulated store: it is not odometryd, and nothing reaches a real store).
  std::string log_prefix = "odometryd: selfcal: ";
  std::string stored_note = " (stored)";
};

// wall_clock_seconds: the record time of an online calibration [s since 1970, UTC].
using WallClock = std::int64_t (*)();

class SelfCalEstimator {
 public:
  // store: where accepted calibrations are written (null: applied but not stored).
  SelfCalEstimator(const SelfCalSetup& s, calib::CalibrationStore* store,
                   loop::CommandQueue& commands, loop::SegmentRing& segments,
                   const loop::RecordingEncoder& recorder, std::ostream& log,
                   WallClock clock = nullptr);
  ~SelfCalEstimator() { stop(); }
  SelfCalEstimator(const SelfCalEstimator&) = delete;
  SelfCalEstimator& operator=(const SelfCalEstimator&) = delete;

  // fix_ring: the loop thread's lock-free way in (the CAN broadcaster is its producer).
  FixRing& fix_ring() noexcept { return ring_; }
  // submit: a fix from any thread but the loop's (takes a mutex).
  void submit(const calib::PoseFix& f);
  // step: one pass: take segments and ripe fixes, fit when due, apply an accepted candidate.
  void step();
  // start / stop: a thread that steps every `period` [s] until stop() (stop steps once more).
  void start(double period = 0.05);
  void stop();
  SelfCalCounters counters() const;
  // in_use: the kinematic parameters the estimator believes the loop runs on.
  KinematicParams in_use() const;
  // Backlog: what the estimator holds between fits (its memory grows with these only).
  struct Backlog {
    std::size_t segments = 0;  // count segments kept for the window
    std::size_t window = 0;    // fixes in the window (<= max_fixes)
    std::size_t pending = 0;   // fixes not ripe yet
  };
  // backlog: from the estimator's thread, or while it is not running (soak and tests).
  Backlog backlog() const noexcept {
    return {window_.segment_count(), window_.fixes().size(), window_.pending_count()};
  }

 private:
  void take_fixes(TimeNs until);
  void fit();
  void apply(const calib::SelfCalResult& r);

  SelfCalSetup s_;
  calib::CalibrationStore* store_;
  loop::CommandQueue& commands_;
  loop::SegmentRing& segments_;
  const loop::RecordingEncoder& recorder_;
  std::ostream& log_;
  WallClock clock_;
  FixRing ring_;

  mutable std::mutex m_;  // submitted_, counters_, s_.in_use
  std::vector<calib::PoseFix> submitted_;
  SelfCalCounters counters_;

  // Estimator thread only.
  calib::FixWindow window_;

  std::thread thread_;
  std::condition_variable cv_;
  bool done_ = false;
};

}  // namespace odo::fw

namespace odo::loop {
class OdometryLoop;
}

namespace odo::fw {

class CanLink;
struct OpenStore;

// SelfCalLink: [selfcal] wired into odometryd: the recording encoder the loop reads through,
// the segment ring, the store the estimator writes to and the estimator itself.
class SelfCalLink {
 public:
  ~SelfCalLink();
  // create: wraps `encoder` (the rig's); in_use: the kinematics the loop starts with.
  static Result<std::unique_ptr<SelfCalLink>> create(const Config& cfg,
                                                     const KinematicParams& in_use,
                                                     EncoderSource& encoder, std::ostream& log);
  // encoder: what the loop must read.
  EncoderSource& encoder() noexcept { return *recorder_; }
  // attach: the estimator on `loop`'s command queue, fed by `can`'s fixes (may be null).
  void attach(loop::OdometryLoop& loop, CanLink* can);
  void start() { estimator_->start(); }
  void stop() { estimator_->stop(); }
  SelfCalEstimator& estimator() noexcept { return *estimator_; }
  const std::string& describe() const noexcept { return describe_; }

 private:
  SelfCalLink() = default;
  SelfCalSetup setup_;
  std::unique_ptr<OpenStore> store_;
  std::unique_ptr<loop::SegmentRing> segments_;
  std::unique_ptr<loop::RecordingEncoder> recorder_;
  std::unique_ptr<SelfCalEstimator> estimator_;
  std::ostream* log_ = nullptr;
  std::string describe_;
};

}  // namespace odo::fw
