// odomctl calib fit-fixes: self-calibration from absolute fixes offline (issue 18), with the
// daemon's recorder and estimator on a replay count log and a CSV of fixes.
#include <algorithm>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <numbers>
#include <random>
#include <sstream>

#include <nlohmann/json.hpp>

#include "commands.hpp"
#include "odo/analysis/selfcal_tools.hpp"
#include "odo/analysis/umbmark_tools.hpp"
#include "odo/calibration/selfcal.hpp"
#include "odo/firmware/selfcal_estimator.hpp"
#include "odo/hal/angle.hpp"
#include "odo/loop/loop.hpp"
#include "odo/sim/floor.hpp"
#include "odo/sim/sim_encoder.hpp"
#include "odo/sim/sim_nv_storage.hpp"
#include "odo/sim/virtual_clock.hpp"

namespace odo::ctl {
namespace {

struct FitFixesOpts {
  std::string ticks, fixes;
  KinematicsOpts kin;
  calib::SelfCalConfig fit;
  bool json = false;
  std::string icr_text = "fixed";  // --x-icr as typed; parsed into fit.icr
};

// fixes_in_span: every fix lies within the count log's time span (a fix outside it has no
// counts to be predicted from: a clock offset or the wrong log). The message names the fix by
// its data row.
Status fixes_in_span(const std::vector<calib::PoseFix>& fixes, const analysis::LogSpan& span,
                     const FitFixesOpts& o) {
  for (std::size_t i = 0; i < fixes.size(); ++i) {
    if (fixes[i].t >= span.first && fixes[i].t <= span.last) continue;
    std::ostringstream m;
    m << o.fixes << ": fix " << i + 1 << " at t = " << to_seconds(fixes[i].t)
      << " s is outside the time span of " << o.ticks << " [" << to_seconds(span.first) << ", "
      << to_seconds(span.last) << "] s (are both on the same clock?)";
    return make_error(Errc::kInvalidArgument, m.str());
  }
  return Ok{};
}

// fit_input: kinematics, segments and fixes; false (message printed) on bad input.
bool fit_input(const FitFixesOpts& o, calib::FixTrack& track, calib::SelfCalConfig& c) {
  const char* cmd = "odomctl calib fit-fixes: ";
  auto k = make_kinematics(o.kin);
  if (!k) {
    std::cerr << cmd << k.error().message << "\n";
    return false;
  }
  std::ifstream ticks(o.ticks, std::ios::binary), fixes(o.fixes, std::ios::binary);
  for (const auto& [f, name] : {std::pair{&ticks, &o.ticks}, std::pair{&fixes, &o.fixes}}) {
    if (!*f) {
      std::cerr << cmd << *name << ": cannot open\n";
      return false;
    }
  }
  analysis::LogSpan span;
  auto segs = analysis::read_count_segments(ticks, o.ticks, *k, o.kin.bits, &span);
  if (!segs) {
    std::cerr << cmd << segs.error().message << "\n";
    return false;
  }
  auto fx = analysis::read_fixes(fixes, o.fixes);
  if (!fx) {
    std::cerr << cmd << fx.error().message << "\n";
    return false;
  }
  if (auto s = fixes_in_span(*fx, span, o); !s) {
    std::cerr << cmd << s.error().message << "\n";
    return false;
  }
  auto t = calib::build_track(*segs, *fx);
  if (!t) {
    std::cerr << cmd << o.fixes << ": " << t.error().message << "\n";
    return false;
  }
  track = std::move(t).value();
  c = o.fit;
  KinematicsOpts nominal = o.kin;  // metres per count of the nominal wheel: factors 1
  nominal.cl = nominal.cr = 1.0;
  c.metres_per_count = make_kinematics(nominal)->metres_per_count();
  c.in_use = {o.kin.cl, o.kin.cr, o.kin.wheelbase};
  c.x_icr = k->x_icr();  // --config's [robot] x_icr (0 without): the model the log ran with
  if (auto s = calib::check_selfcal_config(c); !s) {
    std::cerr << cmd << s.error().message << "\n";
    return false;
  }
  return true;
}

// failed_bound: for a too-uncertain verdict, which standard deviation (given the scale) was
// above which bound, e.g. "sigma(b | scale) = 0.00031 m > max_sigma_wheelbase = 0.0002 m".
std::string failed_bound(const calib::SelfCalResult& r, const calib::SelfCalConfig& c) {
  const auto i = static_cast<std::size_t>(r.too_uncertain);
  const char* names[] = {"c_l", "c_r", "b"};
  const bool b = i == 2;
  std::ostringstream m;
  m << "sigma(" << names[i] << " | scale) = " << r.sigma_given_scale[i] << (b ? " m" : "") << " > "
    << (b ? "max_sigma_wheelbase = " : "max_sigma_factor = ")
    << (b ? c.max_sigma_wheelbase : c.max_sigma_factor) << (b ? " m" : "");
  return m.str();
}

// icr_reason: why a fitted x_ICR is not applied, e.g. "not observable from these fixes:
// sigma(x_icr) = 0.0031 m > max_sigma_x_icr = 0.002 m"; empty when it is.
std::string icr_reason(const calib::SelfCalResult& r, const calib::SelfCalConfig& c) {
  if (r.x_icr_observable) return {};
  std::ostringstream m;
  m << "not observable from these fixes: sigma(x_icr) = " << r.sigma_x_icr
    << " m > max_sigma_x_icr = " << c.max_sigma_x_icr
    << " m (only excursions whose net turn is not 0 or 360 deg show it: more of those)";
  return m.str();
}

// add_icr_json: x_ICR's estimate, sigma and whether it is applied (with the reason) into j.
void add_icr_json(nlohmann::json& j, const calib::SelfCalResult& r, const calib::SelfCalConfig& c) {
  j["x_icr"] = r.x_icr;
  j["sigma_x_icr"] = r.sigma_x_icr;
  j["x_icr_observable"] = r.x_icr_observable;
  if (!r.x_icr_observable) j["x_icr_reason"] = icr_reason(r, c);
}

// print_icr: the x_ICR line: estimate and sigma [mm], the simulator's value when known, and
// whether an accepted calibration carries it.
void print_icr(const calib::SelfCalResult& r, const calib::SelfCalConfig& c, const double* truth) {
  std::ostringstream m;
  m << std::fixed << std::setprecision(2) << "x_icr       " << r.x_icr * 1e3 << " mm (sigma "
    << r.sigma_x_icr * 1e3 << " mm";
  if (truth) m << ", friction model's spot turn " << *truth * 1e3 << " mm";
  m << "): " << (r.x_icr_observable ? "observable, applied with the rest" : icr_reason(r, c))
    << "\n";
  std::cout << m.str();
}

void print_result(const calib::SelfCalResult& r, const calib::SelfCalConfig& c, bool as_json) {
  std::vector<int> rejected;  // fix numbers, 1 = the first data row of FIXES.csv
  for (int i : r.rejected) rejected.push_back(i + 1);
  if (as_json) {
    nlohmann::json j{{"c_l", r.estimate.c_l},
                     {"c_r", r.estimate.c_r},
                     {"wheelbase", r.estimate.wheelbase},
                     {"sigma_c_l", r.sigma[0]},
                     {"sigma_c_r", r.sigma[1]},
                     {"sigma_wheelbase", r.sigma[2]},
                     {"sigma_given_scale", r.sigma_given_scale},
                     {"scale_learnt", r.scale_learnt},
                     {"fixes_used", r.fixes_used},
                     {"fixes_rejected", r.fixes_rejected},
                     {"rejected", rejected},
                     {"excursions_fit", r.excursions_fit},
                     {"excursions_held_out", r.excursions_held_out},
                     {"excursions_skipped", r.excursions_skipped},
                     {"chi2_per_dof", r.chi2_per_dof},
                     {"held_out_candidate", r.score_candidate},
                     {"held_out_in_use", r.score_in_use},
                     {"verdict", calib::verdict_name(r.verdict)}};
    if (r.too_uncertain >= 0) j["failed_bound"] = failed_bound(r, c);
    if (c.icr == calib::IcrFit::kFit) add_icr_json(j, r, c);
    std::cout << j.dump() << "\n";
    return;
  }
  std::cout << "c_l         " << r.estimate.c_l << " (sigma " << r.sigma[0] << ")\n"
            << "c_r         " << r.estimate.c_r << " (sigma " << r.sigma[1] << ")\n"
            << "wheelbase   " << r.estimate.wheelbase << " m (sigma " << r.sigma[2] << " m)\n"
            << "given scale sigma c_l " << r.sigma_given_scale[0] << ", c_r "
            << r.sigma_given_scale[1] << ", b " << r.sigma_given_scale[2]
            << " m (what the acceptance bounds test)\n"
            << "scale       " << std::lround(100.0 * r.scale_learnt)
            << " % of its information from the fixes (0 %: the prior's, the values in use)\n"
            << "fixes       " << r.fixes_used << " used, " << r.fixes_rejected << " rejected";
  for (std::size_t i = 0; i < rejected.size(); ++i)
    std::cout << (i == 0 ? " (fix " : ", ") << rejected[i] << (i + 1 == rejected.size() ? ")" : "");
  std::cout << "\nexcursions  " << r.excursions_fit << " fit, " << r.excursions_held_out
            << " held out, " << r.excursions_skipped << " skipped\n"
            << "residual    chi2/dof " << r.chi2_per_dof << " (fit); held out " << r.score_candidate
            << " against " << r.score_in_use << " with the values in use\n"
            << "verdict     " << calib::verdict_name(r.verdict);
  if (r.too_uncertain >= 0) std::cout << ": " << failed_bound(r, c);
  std::cout << "\n";
  if (c.icr == calib::IcrFit::kFit) print_icr(r, c, nullptr);
}

void run_fit_fixes(FitFixesOpts& o, int& exit_code) {
  if (!take_choice(parse_choice_of<calib::IcrFit>(calib::kIcrFitNames, "--x-icr", o.icr_text),
                   o.fit.icr, "calib fit-fixes", exit_code))
    return;
  calib::FixTrack track;
  calib::SelfCalConfig c;
  if (!fit_input(o, track, c)) {
    exit_code = kExitBadInput;
    return;
  }
  auto r = calib::fit_fixes(track, c);
  if (!r) {
    std::cerr << "odomctl calib fit-fixes: " << r.error().message << "\n";
    exit_code = kExitFailed;
    return;
  }
  print_result(*r, c, o.json);
  exit_code = kExitOk;
}

struct SelfcalOpts {
  int excursions = 20;
  double sigma_xy = 0.005;   // [m]
  double sigma_theta = 0.5;  // [deg]
  double outliers = 0.0;     // fraction of fixes moved 0.5 .. 5 m
  double late = 0.3;         // [s] a fix arrives this long after its moment
  bool smooth = false;       // no floor roughness
  int min_fixes = 0;         // 0: excursions + 1 (one fit at the end)
  int fit_every = 4;
  int score_runs = 200;  // squares a direction of the systematic E_max,syst
  std::uint64_t seed = 1;
  bool json = false;
  std::string plot;                    // SVG of the convergence, empty: none
  std::string scenario_text = "dock";  // as typed; parsed into `scenario`
  analysis::SelfCalScenario scenario = analysis::SelfCalScenario::kDock;
  bool direct_drive = false;           // open: encoders on the wheels (else geared)
  std::string ticks_out, fixes_out;    // open: the count log and fixes fit-fixes reads
  std::string robot_text = "labmate";  // as typed; parsed into `robot`
  analysis::UmbmarkRobot robot = analysis::UmbmarkRobot::kLabmate;
  double com_x = 0.0;  // skid4: centre of mass ahead of the geometric centre [m]
};

// SimDrive: the random excursions as one scenario and the fix moments (ticks in the final
// pause of each excursion, and one at the start).
struct SimDrive {
  sim::Scenario scenario;
  std::vector<TimeNs> fix_times;
};

SimDrive plan_drive(const SelfcalOpts& o, std::mt19937_64& rng) {
  SimDrive d;
  d.scenario.push_back({0.5, 0.0, 0.0});
  d.fix_times.push_back(from_seconds(0.3));
  Pose2 pose;
  for (int e = 0; e < o.excursions; ++e) {
    const sim::Scenario ex = analysis::random_excursion(rng, pose);
    d.scenario.insert(d.scenario.end(), ex.begin(), ex.end());
    d.scenario.push_back({0.5, 0.0, 0.0});
    const double end = sim::scenario_duration(d.scenario);
    d.fix_times.push_back(from_seconds(std::round((end - 0.3) * 100.0) / 100.0));
    auto r = *sim::SimRobot::create(sim::labmate_geometry(analysis::kSelfCalDn), d.scenario);
    r.advance_to(from_seconds(end));
    pose = r.true_pose();  // the planner's view (no floor): any planner will do
  }
  return d;
}

struct SimOutcome {
  fw::SelfCalCounters counters;
  KinematicParams final;
  std::string log;
  int corrupted = 0;
  std::vector<analysis::SelfCalFitPoint> history;  // every completed fit, in order
};

// record_fit: after a step of the estimator, its fit (if it ran one and the fit succeeded)
// into `out.history`; collected here, on the command's thread, from the estimator's counters.
void record_fit(const fw::SelfCalEstimator& est, fw::SelfCalCounters& seen, SimOutcome& out) {
  fw::SelfCalCounters now = est.counters();
  if (now.fits - now.fit_errors > seen.fits - seen.fit_errors && now.last) {
    const calib::SelfCalResult& r = *now.last;
    // The first fix is taken at the dock before any excursion.
    const int driven = std::max(static_cast<int>(now.fixes_received) - 1, 0);
    out.history.push_back({driven, r.estimate, r.sigma, now.accepted > seen.accepted});
  }
  seen = std::move(now);
}

// selfcal_setup: the estimator as the daemon would run it for these options.
fw::SelfCalSetup selfcal_setup(const SelfcalOpts& o, const Kinematics& believed) {
  fw::SelfCalSetup setup;
  setup.cfg.enabled = true;
  setup.cfg.min_fixes = o.min_fixes > 0 ? o.min_fixes : o.excursions + 1;
  setup.cfg.max_fixes = std::max(setup.cfg.min_fixes, 41);
  setup.cfg.fit_every = o.fit_every;
  setup.nominal = setup.in_use = believed.params();
  setup.ripe_delay = from_seconds(0.04);
  setup.log_prefix = "odomctl selfcal simulate: ";
  setup.stored_note = " (in the simulation's store only)";
  return setup;
}

// make_fix: a fix of the true pose at `now` with the options' noise; when `may_corrupt`, with
// probability --outliers a wrong landmark match 0.5-5 m off (counted in `corrupted`).
calib::PoseFix make_fix(const SelfcalOpts& o, const Pose2& truth, TimeNs now, bool may_corrupt,
                        std::mt19937_64& rng, int& corrupted) {
  std::normal_distribution<double> n01;
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const double sth = o.sigma_theta * kRadPerDeg;
  calib::PoseFix f{now,
                   truth.x + o.sigma_xy * n01(rng),
                   truth.y + o.sigma_xy * n01(rng),
                   wrap_angle(truth.theta + sth * n01(rng)),
                   o.sigma_xy,
                   sth};
  if (may_corrupt && u(rng) < o.outliers) {
    const double r = 0.5 + 4.5 * u(rng), a = 2 * std::numbers::pi * u(rng);
    f.x += r * std::cos(a);
    f.y += r * std::sin(a);
    ++corrupted;
  }
  return f;
}

// simulate_drive: the daemon's loop, recorder and estimator on the simulated LabMate.
SimOutcome simulate_drive(const SelfcalOpts& o, const SimDrive& d, std::mt19937_64& rng) {
  const Kinematics believed = analysis::selfcal_kinematics({1.0, 1.0, analysis::kSelfCalBn});
  sim::VirtualClock clock;
  auto robot = *sim::SimRobot::create(sim::labmate_geometry(analysis::kSelfCalDn), d.scenario);
  sim::UmbmarkFloor::Options fo;
  fo.roughness_height = o.smooth ? 0.0 : analysis::kPaperRoughness;
  sim::UmbmarkFloor floor(fo, o.seed * 1000);
  robot.set_travel_perturbation(&floor);
  sim::SimEncoderSource enc(robot, 32);
  loop::SegmentRing segments(8192);
  loop::RecordingEncoder rec(enc, *calib::recorder_limits(believed), segments);
  auto lp = loop::OdometryLoop::create(loop::LoopConfig{}, believed, rec, clock).value();
  sim::SimNvStorage medium(sim::SimMedium::kEeprom, 1024, 0, 16);
  auto store = *calib::CalibrationStore::create(medium);
  std::ostringstream log;
  fw::SelfCalEstimator est(selfcal_setup(o, believed), &store, lp->commands(), segments, rec, log);
  std::vector<calib::PoseFix> waiting;
  SimOutcome out;
  fw::SelfCalCounters seen;
  std::size_t next = 0;
  lp->start();
  const TimeNs end = from_seconds(sim::scenario_duration(d.scenario) + 1.0);
  while (lp->snapshot().stamp < end) {
    lp->tick();
    const TimeNs now = lp->snapshot().stamp;
    if (next < d.fix_times.size() && now >= d.fix_times[next]) {
      waiting.push_back(make_fix(o, robot.true_pose(), now, next > 0, rng, out.corrupted));
      ++next;
    }
    if (!waiting.empty() && now >= waiting.front().t + from_seconds(o.late)) {
      est.submit(waiting.front());
      waiting.erase(waiting.begin());
    }
    if (lp->snapshot().tick % 5 == 0) {
      est.step();
      record_fit(est, seen, out);
    }
  }
  est.step();
  record_fit(est, seen, out);
  out.counters = est.counters();
  out.final = est.in_use();
  out.log = log.str();
  return out;
}

// Scores: E_max,syst [m] of the nominal, self-calibrated and manually calibrated robot.
struct Scores {
  double e5[3];     // by the report's 5 + 5 squares
  double e_sys[3];  // by score_runs + score_runs squares
};

// score: the three calibrations scored (NaN for the manual pass if its simulation failed).
Scores score(const SelfcalOpts& o, const calib::Factors& fin) {
  analysis::UmbmarkSimOptions uo;
  uo.noise = o.smooth ? analysis::UmbmarkNoise::kNone : analysis::UmbmarkNoise::kPaper;
  uo.seed = o.seed;
  auto manual = analysis::run_umbmark_simulation(uo);
  // E_max,syst of the nominal, self-calibrated and manually calibrated robot: by the report's
  // 5 + 5 squares, and by score_runs + score_runs (the same floor statistics; the systematic
  // error, which 5 + 5 squares on the rough floor measure only to ~5 mm: BENCHMARKS.md).
  const calib::Factors cal[] = {
      {1.0, 1.0, analysis::kSelfCalBn},
      fin,
      manual ? manual->passes[0].result.composed : calib::Factors{NAN, NAN, NAN}};
  Scores sc;
  for (int i = 0; i < 3; ++i) {
    const bool ok = i < 2 || manual;
    sc.e5[i] = ok ? analysis::selfcal_e_max_syst(cal[i], !o.smooth) : NAN;
    sc.e_sys[i] = ok ? analysis::selfcal_e_max_syst(cal[i], !o.smooth, o.score_runs, 100000) : NAN;
  }
  return sc;
}

// write_plot: --plot, the convergence with E_max,syst (5 + 5 and score_runs + score_runs
// squares: nominal, self-calibrated, one manual pass) as notes; false (said) when not written.
bool write_plot(const SelfcalOpts& o, const SimOutcome& r, const Scores& sc) {
  const double *e5 = sc.e5, *e_sys = sc.e_sys;
  std::ostringstream title, n5, nsys;
  title << "odomctl selfcal simulate: " << o.excursions << " excursions, fixes sigma "
        << o.sigma_xy * 1e3 << " mm / " << o.sigma_theta << " deg, " << o.outliers * 100
        << " % corrupted, " << (o.smooth ? "smooth" : "rough") << " floor, seed " << o.seed;
  n5 << std::setprecision(4) << "E_max,syst (5 + 5 squares): nominal " << e5[0] * 1e3
     << " mm, self-calibrated " << e5[1] * 1e3 << " mm, one manual UMBmark pass " << e5[2] * 1e3
     << " mm";
  nsys << std::setprecision(4) << "E_max,syst (" << o.score_runs << " + " << o.score_runs
       << " squares): nominal " << e_sys[0] * 1e3 << " mm, self-calibrated " << e_sys[1] * 1e3
       << " mm, one manual UMBmark pass " << e_sys[2] * 1e3 << " mm";
  std::ostringstream fits;
  fits << r.history.size() << " fits, "
       << std::count_if(r.history.begin(), r.history.end(),
                        [](const analysis::SelfCalFitPoint& p) { return p.applied; })
       << " applied";
  const std::string svg = analysis::selfcal_svg(r.history, analysis::selfcal_truth(),
                                                {fits.str(), n5.str(), nsys.str()}, title.str());
  return write_output_file(o.plot, svg, "selfcal simulate");
}

// fit_fixes_command: the `calib fit-fixes` line that fits the files of an open drive.
std::string fit_fixes_command(const SelfcalOpts& o, const analysis::FixDrive& d,
                              const calib::SelfCalConfig& c) {
  std::ostringstream m;
  m << "odomctl calib fit-fixes --ticks " << o.ticks_out << " --fixes " << o.fixes_out
    << " --wheel-diameter " << d.nominal.wheel_diameter << " --counts-per-rev "
    << d.geometry.counts_per_rev << " --gear-ratio " << d.geometry.gear_ratio << " --wheelbase "
    << d.nominal.wheelbase << " --k-left " << c.odometry_noise.k_left << " --k-right "
    << c.odometry_noise.k_right;
  if (c.icr == calib::IcrFit::kFit) m << " --x-icr fit";
  return m.str();
}

// SkidScore: --robot skid4: the square's return error with the guessed and the self-calibrated
// track, and the friction model's tracks of the drive's and the squares' spot turns.
struct SkidScore {
  analysis::UmbmarkSquares guess, selfcal;
  double drive_spot_turn = 0.0;  // [m]
};

// skid_score: one cw and one ccw square (noiseless runs are identical) of 4 m on skid4 with the
// geometric track x 1.5 and with the estimate; false (said) when a square failed.
bool skid_score(const analysis::FixDrive& d, const calib::Factors& estimate, SkidScore& out) {
  analysis::UmbmarkSimOptions uo;
  uo.robot = analysis::UmbmarkRobot::kSkid4;
  uo.runs = 1;
  auto guess = analysis::score_umbmark_factors(uo, {1.0, 1.0, d.nominal.wheelbase});
  auto cal = analysis::score_umbmark_factors(uo, estimate);
  for (const auto* r : {&guess, &cal}) {
    if (!*r) {
      std::cerr << "odomctl selfcal simulate: " << r->error().message << "\n";
      return false;
    }
  }
  out.guess = std::move(guess).value();
  out.selfcal = std::move(cal).value();
  out.drive_spot_turn = d.spot_turn_angle > 0.0 ? d.spot_turn_rim / d.spot_turn_angle : 0.0;
  return true;
}

nlohmann::json skid_score_json(const analysis::FixDrive& d, const calib::Factors& estimate,
                               const SkidScore& k) {
  const double before = k.guess.set.e_max_syst, after = k.selfcal.set.e_max_syst;
  return {{"geometric_track", d.geometry.wheelbase},
          {"guessed_track", d.nominal.wheelbase},
          {"found_track", estimate.wheelbase},
          {"drive_spot_turn_track", k.drive_spot_turn},
          {"square_spot_turn_track", k.selfcal.spot_turn},
          {"e_max_syst_guess", before},
          {"e_max_syst_selfcal", after},
          {"improvement", after > 0.0 ? before / after : 0.0},
          {"unconverged", d.unconverged + k.guess.unconverged + k.selfcal.unconverged}};
}

void print_skid_score(const analysis::FixDrive& d, const calib::Factors& estimate,
                      const SkidScore& k) {
  const double found = estimate.wheelbase, spot = k.selfcal.spot_turn;
  const double before = k.guess.set.e_max_syst, after = k.selfcal.set.e_max_syst;
  std::ostringstream m;
  m << std::fixed << std::setprecision(1) << "track [mm] geometric " << d.geometry.wheelbase * 1e3
    << ", guess x" << analysis::kSkidTrackMultiplier << " " << d.nominal.wheelbase * 1e3
    << ", self-calibration found " << found * 1e3 << "; friction model in the drive's spot turns "
    << k.drive_spot_turn * 1e3 << ", in the square's " << spot * 1e3 << std::setprecision(2)
    << " (found " << std::showpos << 100.0 * (found - spot) / spot << std::noshowpos << " %)\n"
    << "square      E_max,syst (4 m, 1 + 1 squares) " << before * 1e3
    << " mm with the guessed track, " << after * 1e3 << " mm self-calibrated ("
    << std::setprecision(1) << (after > 0.0 ? before / after : 0.0) << "x)\n";
  const std::uint64_t bad = d.unconverged + k.guess.unconverged + k.selfcal.unconverged;
  if (bad > 0) m << "unconverged friction solves: " << bad << "\n";
  std::cout << m.str();
}

// print_open: the open scenario's outcome (--json or text): the estimate against the drive's
// truth, and with k (--robot skid4) the tracks and the square's return errors.
void print_open(const SelfcalOpts& o, const analysis::FixDrive& d, const calib::SelfCalConfig& c,
                const calib::SelfCalResult& r, const SkidScore* k) {
  const int corrupted = static_cast<int>(std::count(d.corrupted.begin(), d.corrupted.end(), true));
  if (o.json) {
    nlohmann::json j{{"scenario", "open"},
                     {"excursions", o.excursions},
                     {"fixes", d.fixes.size()},
                     {"corrupted", corrupted},
                     {"rejected", r.rejected},
                     {"c_l", r.estimate.c_l},
                     {"c_r", r.estimate.c_r},
                     {"wheelbase", r.estimate.wheelbase},
                     {"sigma", r.sigma},
                     {"scale_learnt", r.scale_learnt},
                     {"truth_c_l", d.truth.c_l},
                     {"truth_c_r", d.truth.c_r},
                     {"truth_wheelbase", d.truth.wheelbase},
                     {"verdict", calib::verdict_name(r.verdict)}};
    if (k) j["skid"] = skid_score_json(d, r.estimate, *k);
    if (c.icr == calib::IcrFit::kFit) {
      add_icr_json(j, r, c);
      j["truth_x_icr"] = d.truth_x_icr;
      j["com_x"] = o.com_x;
    }
    std::cout << j.dump() << "\n";
  } else {
    std::cout << "excursions  " << o.excursions << " open, fixes " << d.fixes.size() << " ("
              << corrupted << " corrupted, " << r.fixes_rejected << " rejected)\n"
              << "c_l         " << r.estimate.c_l << " (sigma " << r.sigma[0] << ", truth "
              << d.truth.c_l << ")\n"
              << "c_r         " << r.estimate.c_r << " (sigma " << r.sigma[1] << ", truth "
              << d.truth.c_r << ")\n"
              << "wheelbase   " << r.estimate.wheelbase << " m (sigma " << r.sigma[2]
              << " m, truth " << d.truth.wheelbase << " m)\n"
              << "scale       " << std::lround(100.0 * r.scale_learnt)
              << " % of its information from the fixes\n"
              << "verdict     " << calib::verdict_name(r.verdict)
              << (r.too_uncertain >= 0 ? ": " + failed_bound(r, c) : std::string()) << "\n";
    if (c.icr == calib::IcrFit::kFit) print_icr(r, c, &d.truth_x_icr);
    if (k) print_skid_score(d, r.estimate, *k);
    if (!o.ticks_out.empty() && !o.fixes_out.empty())
      std::cout << "fit them    " << fit_fixes_command(o, d, c) << "\n";
  }
}

// run_open: --scenario open: a random robot (c_L, c_R up to 0.6 % off, b 1.5 %) drives open
// excursions with a fix where each ends; the fixes are fit as `calib fit-fixes` would, and
// --ticks-out / --fixes-out write the files it reads.
void run_open(const SelfcalOpts& o, int& exit_code) {
  analysis::FixDriveOptions fo;
  fo.excursions = o.excursions;
  fo.sigma_xy = o.sigma_xy;
  fo.sigma_theta = o.sigma_theta * kRadPerDeg;
  fo.outliers = o.outliers;
  fo.direct_drive = o.direct_drive;
  fo.seed = o.seed;
  fo.robot = o.robot;
  fo.com_x = o.com_x;
  const analysis::FixDrive d = analysis::simulate_fix_drive(fo);
  const calib::SelfCalConfig c = analysis::fix_drive_config(d, fo);
  const char* cmd = "selfcal simulate";
  if ((!o.ticks_out.empty() &&
       !write_output_file(o.ticks_out, analysis::count_log_csv(d.ticks), cmd)) ||
      (!o.fixes_out.empty() &&
       !write_output_file(o.fixes_out, analysis::fixes_csv(d.fixes), cmd))) {
    exit_code = kExitFailed;
    return;
  }
  auto t = calib::build_track(d.segments, d.fixes);
  auto r = t ? calib::fit_fixes(*t, c) : Result<calib::SelfCalResult>(t.error());
  if (!r) {
    std::cerr << "odomctl selfcal simulate: " << r.error().message << "\n";
    exit_code = kExitFailed;
    return;
  }
  // The square is scored on the centred base (UMBmark's skid4): with a load off centre it would
  // score the estimate on another robot, so then x_ICR is the figure.
  const bool skid = o.robot == analysis::UmbmarkRobot::kSkid4 && o.com_x == 0.0;
  SkidScore k;
  if (skid && !skid_score(d, r->estimate, k)) {
    exit_code = kExitFailed;
    return;
  }
  print_open(o, d, c, *r, skid ? &k : nullptr);
  exit_code = kExitOk;
}

// print_dock: the dock scenario's outcome (--json or text): counters, the factors against the
// simulation's truth, E_max,syst [m] nominal, self-calibrated and after a manual pass.
void print_dock(const SelfcalOpts& o, const SimOutcome& r, const calib::Factors& fin,
                const Scores& sc) {
  const calib::Factors truth = analysis::selfcal_truth();
  const double *e5 = sc.e5, *e_sys = sc.e_sys;
  const double before = e5[0], after = e5[1], e_manual = e5[2];
  const fw::SelfCalCounters& c = r.counters;
  if (o.json) {
    nlohmann::json j{{"excursions", o.excursions},
                     {"fixes", c.fixes_received},
                     {"corrupted", r.corrupted},
                     {"rejected", c.fixes_rejected},
                     {"fits", c.fits},
                     {"fit_errors", c.fit_errors},
                     {"applied", c.accepted},
                     {"c_l", fin.c_l},
                     {"c_r", fin.c_r},
                     {"wheelbase", fin.wheelbase},
                     {"truth_c_l", truth.c_l},
                     {"truth_c_r", truth.c_r},
                     {"truth_wheelbase", truth.wheelbase},
                     {"e_max_syst_before", before},
                     {"e_max_syst_after", after},
                     {"e_max_syst_manual_pass", e_manual},
                     {"score_runs", o.score_runs},
                     {"e_max_syst_systematic_before", e_sys[0]},
                     {"e_max_syst_systematic_after", e_sys[1]},
                     {"e_max_syst_systematic_manual_pass", e_sys[2]}};
    std::cout << j.dump() << "\n";
  } else {
    std::cout << r.log << "excursions  " << o.excursions << ", fixes " << c.fixes_received << " ("
              << r.corrupted << " corrupted, " << c.fixes_rejected << " rejected), fits " << c.fits
              << ", applied " << c.accepted << "\n"
              << "c_l         " << fin.c_l << " (truth " << truth.c_l << ")\n"
              << "c_r         " << fin.c_r << " (truth " << truth.c_r << ")\n"
              << "wheelbase   " << fin.wheelbase << " m (truth " << truth.wheelbase << " m)\n"
              << "E_max,syst  " << before * 1e3 << " mm nominal, " << after * 1e3
              << " mm self-calibrated, " << e_manual * 1e3
              << " mm after one manual UMBmark pass (5 + 5 squares)\n"
              << "E_max,syst  " << e_sys[0] * 1e3 << " mm nominal, " << e_sys[1] * 1e3
              << " mm self-calibrated, " << e_sys[2] * 1e3 << " mm after one manual UMBmark pass ("
              << o.score_runs << " + " << o.score_runs << " squares)\n";
  }
}

void run_simulate(const SelfcalOpts& o, int& exit_code) {
  if (!output_paths_ok({o.plot, o.ticks_out, o.fixes_out}, "selfcal simulate")) {
    exit_code = kExitBadInput;
    return;
  }
  if (o.com_x != 0.0 && o.robot != analysis::UmbmarkRobot::kSkid4) {
    std::cerr << "odomctl selfcal simulate: --com-x needs --robot skid4\n";
    exit_code = kExitBadInput;
    return;
  }
  if (o.robot == analysis::UmbmarkRobot::kSkid4 && (o.direct_drive || o.smooth)) {
    std::cerr << "odomctl selfcal simulate: --direct-drive and --smooth-floor are the LabMate's; "
                 "--robot skid4 has its own encoders and a smooth floor\n";
    exit_code = kExitBadInput;
    return;
  }
  if (o.scenario == analysis::SelfCalScenario::kOpen) {
    run_open(o, exit_code);
    return;
  }
  if (!o.ticks_out.empty() || !o.fixes_out.empty() || o.direct_drive) {
    std::cerr << "odomctl selfcal simulate: --ticks-out, --fixes-out and --direct-drive need "
                 "--scenario open (the dock scenario runs the daemon's loop on the LabMate)\n";
    exit_code = kExitBadInput;
    return;
  }
  std::mt19937_64 rng(o.seed);
  const SimDrive d = plan_drive(o, rng);
  const SimOutcome r = simulate_drive(o, d, rng);
  const calib::Factors fin{r.final.c_l, r.final.c_r, r.final.wheelbase};
  const Scores sc = score(o, fin);
  if (!o.plot.empty() && !write_plot(o, r, sc)) {
    exit_code = kExitFailed;
    return;
  }
  print_dock(o, r, fin, sc);
  exit_code = kExitOk;
}

// simulate_choices: --scenario and --robot parsed into o; --robot skid4 drives the open scenario
// (the dock scenario runs the daemon's loop on the LabMate), refused with --scenario dock.
// False (said, exit code set) on bad input.
bool simulate_choices(SelfcalOpts& o, bool scenario_given, int& exit_code) {
  const char* cmd = "selfcal simulate";
  if (!take_choice(parse_choice_of<analysis::SelfCalScenario>(analysis::kSelfCalScenarios,
                                                              "--scenario", o.scenario_text),
                   o.scenario, cmd, exit_code) ||
      !take_choice(parse_choice_of<analysis::UmbmarkRobot>(analysis::kUmbmarkRobots, "--robot",
                                                           o.robot_text),
                   o.robot, cmd, exit_code))
    return false;
  if (o.robot != analysis::UmbmarkRobot::kSkid4) return true;
  if (scenario_given && o.scenario != analysis::SelfCalScenario::kOpen) {
    std::cerr << "odomctl selfcal simulate: --robot skid4 needs --scenario open\n";
    exit_code = kExitBadInput;
    return false;
  }
  o.scenario = analysis::SelfCalScenario::kOpen;
  return true;
}

}  // namespace

void add_selfcal(CLI::App& app, int& exit_code) {
  CLI::App* sc = app.add_subcommand("selfcal", "self-calibration from absolute fixes");
  sc->require_subcommand(1);
  auto o = std::make_shared<SelfcalOpts>();
  CLI::App* c = sc->add_subcommand(
      "simulate", "random excursions from a dock with fixes, through the daemon's estimator");
  fw::with_range(c->add_option("--excursions", o->excursions, "excursions"), 1, 1000)
      ->capture_default_str();
  fw::with_range(c->add_option("--sigma-xy", o->sigma_xy, "fix noise [m]"), 1e-4, 1.0)
      ->capture_default_str();
  fw::with_range(c->add_option("--sigma-theta", o->sigma_theta, "fix heading noise [deg]"), 0.01,
                 20.0)
      ->capture_default_str();
  fw::with_range(c->add_option("--outliers", o->outliers, "fraction of fixes moved 0.5-5 m"), 0.0,
                 0.5)
      ->capture_default_str();
  fw::with_range(c->add_option("--late", o->late, "delay of every fix [s]"), 0.0, 4.0)
      ->capture_default_str();
  c->add_flag("--smooth-floor", o->smooth, "no floor roughness (without it: the report's floor)");
  fw::with_range(
      c->add_option("--min-fixes", o->min_fixes, "fixes before the first fit, 0 = excursions + 1"),
      0, 1000)
      ->capture_default_str();
  fw::with_range(c->add_option("--fit-every", o->fit_every, "a fit after every n new fixes"), 1,
                 1000)
      ->capture_default_str();
  fw::with_range(c->add_option("--score-runs", o->score_runs,
                               "squares a direction of the systematic E_max,syst"),
                 5, 1000)
      ->capture_default_str();
  c->add_option("--seed", o->seed, "random seed")->capture_default_str();
  c->add_flag("--json", o->json, "print one JSON object");
  c->add_option("--plot", o->plot, "write an SVG of the estimate's convergence over the fits");
  c->add_option("--scenario", o->scenario_text,
                "dock: the LabMate from a dock through the daemon; open: a random robot, a fix "
                "where each excursion ends")
      ->capture_default_str();
  c->add_option("--robot", o->robot_text,
                "labmate; skid4: the Jackal-sized 4WD skid-steer base, open scenario (its track "
                "found against the geometric track x 1.5)")
      ->capture_default_str();
  fw::with_range(
      c->add_option("--com-x", o->com_x,
                    "skid4: centre of mass ahead of the geometric centre [m] (x_ICR "
                    "found against the friction model's; the square is then not scored)"),
      -0.12, 0.12)
      ->capture_default_str();
  c->add_flag("--direct-drive", o->direct_drive, "open: 4096-count encoders on the wheels");
  c->add_option("--ticks-out", o->ticks_out, "open: write the count log (calib fit-fixes --ticks)");
  c->add_option("--fixes-out", o->fixes_out, "open: write the fixes (calib fit-fixes --fixes)");
  c->callback([o, c, &exit_code] {
    if (simulate_choices(*o, c->count("--scenario") > 0, exit_code)) run_simulate(*o, exit_code);
  });
}

void add_calib_fit_fixes(CLI::App& calib, int& exit_code) {
  auto o = std::make_shared<FitFixesOpts>();
  CLI::App* c = calib.add_subcommand(
      "fit-fixes", "estimate c_L, c_R and b from a count log and absolute pose fixes");
  c->add_option("--ticks", o->ticks, "count log: CSV t,left,right[,gyro_z]")->required();
  c->add_option("--fixes", o->fixes, "fixes: CSV t,x,y,theta,sigma_xy,sigma_theta")->required();
  add_kinematics_options(*c, o->kin,
                         {"wheelbase b in use while recording [m]", "c_L in use while recording",
                          "c_R in use while recording"});
  c->add_option("--k-left", o->fit.odometry_noise.k_left, "wheel noise k_L [m^(1/2)]")
      ->capture_default_str();
  c->add_option("--k-right", o->fit.odometry_noise.k_right, "wheel noise k_R [m^(1/2)]")
      ->capture_default_str();
  c->add_option("--hold-out-every", o->fit.hold_out_every, "hold out every n-th excursion")
      ->capture_default_str();
  c->add_option("--max-sigma-factor", o->fit.max_sigma_factor, "acceptance bound on sigma(c)")
      ->capture_default_str();
  c->add_option("--max-sigma-wheelbase", o->fit.max_sigma_wheelbase,
                "acceptance bound on sigma(b) [m]")
      ->capture_default_str();
  c->add_option("--prior-sigma-factor", o->fit.prior_sigma_factor,
                "prior standard deviation of c_L, c_R around the values in use (the scale's "
                "tolerance)")
      ->capture_default_str();
  c->add_option("--prior-sigma-wheelbase", o->fit.prior_sigma_wheelbase,
                "prior standard deviation of b around the value in use [m]")
      ->capture_default_str();
  fw::say_range(c->add_option("--min-improvement", o->fit.min_improvement,
                              "held-out score below (1 - this) x the values in use"),
                0.0, 0.9)
      ->capture_default_str();
  c->add_option("--x-icr", o->icr_text,
                "skid steer: fixed (the ICR offset in use, --config's [robot] x_icr or 0) or fit "
                "(a 4th parameter, applied when its sigma is below --max-sigma-x-icr)")
      ->capture_default_str();
  c->add_option("--prior-sigma-x-icr", o->fit.prior_sigma_x_icr,
                "prior standard deviation of x_icr around the value in use [m]")
      ->capture_default_str();
  c->add_option("--max-sigma-x-icr", o->fit.max_sigma_x_icr,
                "x_icr is observable (applied) when its sigma is below this [m]")
      ->capture_default_str();
  c->add_flag("--json", o->json, "print one JSON object");
  c->callback([o, &exit_code] { run_fit_fixes(*o, exit_code); });
}

}  // namespace odo::ctl
