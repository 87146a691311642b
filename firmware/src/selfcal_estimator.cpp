#include "odo/firmware/selfcal_estimator.hpp"

#include <algorithm>
#include <chrono>
#include <ctime>

#include "odo/firmware/calibration_store.hpp"
#include "odo/firmware/can_link.hpp"
#include "odo/loop/loop.hpp"

namespace odo::fw {
namespace {

std::int64_t system_seconds() {
  return static_cast<std::int64_t>(std::time(nullptr));
}

// metres_per_count: c_m of `p` without the wheel factors (what fit_fixes scales).
double nominal_metres_per_count(KinematicParams p) {
  p.c_l = p.c_r = 1.0;
  auto k = Kinematics::create(p);
  return k ? k->metres_per_count() : 0.0;
}

}  // namespace

SelfCalEstimator::SelfCalEstimator(const SelfCalSetup& s, calib::CalibrationStore* store,
                                   loop::CommandQueue& commands, loop::SegmentRing& segments,
                                   const loop::RecordingEncoder& recorder, std::ostream& log,
                                   WallClock clock)
    : s_(s),
      store_(store),
      commands_(commands),
      segments_(segments),
      recorder_(recorder),
      log_(log),
      clock_(clock != nullptr ? clock : &system_seconds),
      ring_(s.fix_capacity),
      window_({static_cast<std::size_t>(s.cfg.max_fixes), static_cast<std::size_t>(s.cfg.min_fixes),
               static_cast<std::size_t>(s.cfg.fit_every), s.ripe_delay}) {}

void SelfCalEstimator::submit(const calib::PoseFix& f) {
  std::lock_guard lk(m_);
  submitted_.push_back(f);
}

SelfCalCounters SelfCalEstimator::counters() const {
  std::lock_guard lk(m_);
  return counters_;
}

KinematicParams SelfCalEstimator::in_use() const {
  std::lock_guard lk(m_);
  return s_.in_use;
}

void SelfCalEstimator::take_fixes(TimeNs until) {
  calib::PoseFix f;
  std::uint64_t received = 0;
  while (ring_.pop(f)) {
    window_.add_fix(f);
    ++received;
  }
  {
    std::lock_guard lk(m_);
    received += submitted_.size();
    for (const calib::PoseFix& g : submitted_) window_.add_fix(g);
    submitted_.clear();
  }
  const std::uint64_t dropped = window_.take_ripe(until);
  std::lock_guard lk(m_);
  counters_.fixes_received += received;
  counters_.fixes_dropped += dropped;
}

void SelfCalEstimator::step() {
  // Read before draining: every segment the recorder closed up to `until` is in the ring then
  // (it pushes before it publishes the time).
  const TimeNs until = recorder_.recorded_until();
  calib::CountSegment seg;
  std::uint64_t n = 0;
  while (segments_.pop(seg)) {
    window_.add_segment(seg);
    ++n;
  }
  {
    std::lock_guard lk(m_);
    counters_.segments += n;
  }
  take_fixes(until);
  window_.trim(until);
  if (window_.fit_due()) fit();
}

void SelfCalEstimator::fit() {
  calib::SelfCalConfig c;
  KinematicParams use = in_use();
  c.metres_per_count = nominal_metres_per_count(use);
  c.in_use = {use.c_l, use.c_r, use.wheelbase};
  c.prior_sigma_factor = s_.cfg.prior_sigma_factor;
  c.prior_sigma_wheelbase = s_.cfg.prior_sigma_wheelbase;
  c.odometry_noise = s_.noise;
  c.hold_out_every = s_.cfg.hold_out_every;
  c.max_sigma_factor = s_.cfg.max_sigma_factor;
  c.max_sigma_wheelbase = s_.cfg.max_sigma_wheelbase;
  c.min_improvement = s_.cfg.min_improvement;
  c.icr = s_.cfg.x_icr;
  c.x_icr = use.x_icr;  // the model of the kinematics in use, fitted or held
  c.prior_sigma_x_icr = s_.cfg.prior_sigma_x_icr;
  c.max_sigma_x_icr = s_.cfg.max_sigma_x_icr;
  auto track = calib::build_track(window_.segments(), window_.fixes());
  auto r = track ? calib::fit_fixes(*track, c) : Result<calib::SelfCalResult>(track.error());
  std::unique_lock lk(m_);
  ++counters_.fits;
  if (!r) {
    ++counters_.fit_errors;
    lk.unlock();
    log_ << s_.log_prefix << "fit failed: " << r.error().message << std::endl;
    return;
  }
  counters_.fixes_rejected += window_.newly_rejected(r->rejected);
  counters_.last = *r;
  lk.unlock();
  log_ << s_.log_prefix << "" << window_.fixes().size() << " fixes (" << r->fixes_rejected
       << " rejected): c_l=" << r->estimate.c_l << " c_r=" << r->estimate.c_r
       << " b=" << r->estimate.wheelbase << " m, held-out chi2/dof " << r->score_candidate << " vs "
       << r->score_in_use << " in use: " << calib::verdict_name(r->verdict) << std::endl;
  if (c.icr == calib::IcrFit::kFit)
    log_ << s_.log_prefix << "x_icr=" << r->x_icr << " m (sigma " << r->sigma_x_icr << " m): "
         << (r->x_icr_observable ? "observable" : "not observable (sigma above max_sigma_x_icr)")
         << std::endl;
  if (r->verdict == calib::Verdict::kAccepted) apply(*r);
}

void SelfCalEstimator::apply(const calib::SelfCalResult& r) {
  KinematicParams p = in_use();
  p.c_l = r.estimate.c_l;
  p.c_r = r.estimate.c_r;
  p.wheelbase = r.estimate.wheelbase;
  // x_ICR only when the fit saw it; otherwise the value in use stays (and is kept in the record
  // below when it differs from the config's, as the wheel diameter is).
  if (r.x_icr_observable) p.x_icr = r.x_icr;
  auto k = Kinematics::create(p);
  calib::CalibrationRecord rec;
  rec.c_l = p.c_l;
  rec.c_r = p.c_r;
  rec.wheelbase = p.wheelbase;
  if (p.wheel_diameter != s_.nominal.wheel_diameter) rec.wheel_diameter = p.wheel_diameter;
  if (r.x_icr_observable || p.x_icr != s_.nominal.x_icr) rec.x_icr = p.x_icr;
  if (r.x_icr_observable) rec.sigma_x_icr = r.sigma_x_icr;
  rec.time = clock_();
  rec.method = "online";
  rec.fit = calib::FixFitProvenance{static_cast<std::uint32_t>(r.fixes_used),
                                    static_cast<std::uint32_t>(r.fixes_rejected),
                                    r.score_candidate,
                                    r.sigma[0],
                                    r.sigma[1],
                                    r.sigma[2]};
  // Values the store or the kinematics refuse are not applied either: nothing half-done.
  if (auto v = calib::validate_record(rec); !v || !k) {
    log_ << s_.log_prefix << "candidate refused: " << (!k ? k.error().message : v.error().message)
         << std::endl;
    return;
  }
  calib::StoreStatus state = calib::StoreStatus::kUncalibrated;
  if (store_ != nullptr) {
    auto seq = store_->save(rec);
    std::lock_guard lk(m_);
    if (!seq) {
      ++counters_.store_errors;
      log_ << s_.log_prefix
           << "store write failed, calibration not applied: " << seq.error().message << std::endl;
      return;
    }
    ++counters_.written;
    state = calib::StoreStatus::kOk;
  }
  while (!commands_.post(loop::SetKinematics{*k, state}))
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  {
    std::lock_guard lk(m_);
    s_.in_use = p;
    ++counters_.accepted;
  }
  log_ << s_.log_prefix << "applied c_l=" << p.c_l << " c_r=" << p.c_r << " b=" << p.wheelbase
       << " m";
  if (r.x_icr_observable) log_ << " x_icr=" << p.x_icr << " m";
  log_ << (store_ != nullptr ? s_.stored_note : " (no store configured)") << std::endl;
  window_.restart_at_newest();
}

void SelfCalEstimator::start(double period) {
  thread_ = std::thread([this, period] {
    std::unique_lock lk(m_);
    while (!cv_.wait_for(lk, std::chrono::duration<double>(period), [this] { return done_; })) {
      lk.unlock();
      step();
      lk.lock();
    }
  });
}

void SelfCalEstimator::stop() {
  if (!thread_.joinable()) return;
  {
    std::lock_guard lk(m_);
    done_ = true;
  }
  cv_.notify_all();
  thread_.join();
  step();
}

}  // namespace odo::fw

// ---- SelfCalLink ----

namespace odo::fw {

SelfCalLink::~SelfCalLink() {
  if (estimator_) estimator_->stop();
}

Result<std::unique_ptr<SelfCalLink>> SelfCalLink::create(const Config& cfg,
                                                         const KinematicParams& in_use,
                                                         EncoderSource& encoder,
                                                         std::ostream& log) {
  std::unique_ptr<SelfCalLink> l(new SelfCalLink());
  auto k = Kinematics::create(in_use);
  if (!k) return std::move(k).error();
  auto limits = calib::recorder_limits(*k);
  if (!limits) return std::move(limits).error();
  l->setup_.cfg = cfg.selfcal;
  l->setup_.nominal = cfg.robot;
  l->setup_.in_use = in_use;
  l->setup_.noise = cfg.error_model;
  // The open segment closes within max_duration after its last counts, seen one tick later.
  l->setup_.ripe_delay = limits->max_duration + 2 * from_seconds(1.0 / cfg.loop.rate_hz);
  if (!cfg.calibration.store.empty()) {
    auto st = open_calibration_store(cfg.calibration.store, cfg.calibration.backend);
    if (!st) return make_error(st.error().code, "selfcal: " + st.error().message);
    l->store_ = std::make_unique<OpenStore>(std::move(st).value());
  }
  // 8192 segments: 160 s of motion at one segment per 20 ms, for an estimator that stalls.
  l->segments_ = std::make_unique<loop::SegmentRing>(8192);
  l->recorder_ = std::make_unique<loop::RecordingEncoder>(encoder, *limits, *l->segments_);
  l->log_ = &log;
  l->describe_ = "on, fit after " + std::to_string(cfg.selfcal.min_fixes) + " fixes, window " +
                 std::to_string(cfg.selfcal.max_fixes) +
                 (l->store_ ? ", writes " + cfg.calibration.store : std::string(", no store"));
  return l;
}

void SelfCalLink::attach(loop::OdometryLoop& loop, CanLink* can) {
  calib::CalibrationStore* store = store_ && store_->store ? &*store_->store : nullptr;
  estimator_ = std::make_unique<SelfCalEstimator>(setup_, store, loop.commands(), *segments_,
                                                  *recorder_, *log_);
  if (can != nullptr) can->set_fix_ring(&estimator_->fix_ring());
}

}  // namespace odo::fw
