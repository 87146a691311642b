// Offline self-calibration input (`odomctl calib fit-fixes`, issue 18): a replay count log
// recorded into segments by the loop's own recorder, and a CSV of absolute fixes.
#pragma once

#include <array>
#include <cstdint>
#include <istream>
#include <random>
#include <string>
#include <vector>

#include "odo/analysis/umbmark_tools.hpp"
#include "odo/calibration/count_recorder.hpp"
#include "odo/calibration/selfcal.hpp"
#include "odo/hal/choice.hpp"
#include "odo/hal/result.hpp"
#include "odo/odometry/error_model.hpp"
#include "odo/odometry/kinematics.hpp"
#include "odo/odometry/pose.hpp"
#include "odo/sim/robot.hpp"

namespace odo::analysis {

// The time span of a count log: its first and last row [ns].
struct LogSpan {
  TimeNs first = 0, last = 0;
};

// read_count_segments: the replay log `t,left,right` (optionally `gyro_z`, not used yet; t [s]
// non-decreasing, raw `bits`-wide readings) passed reading by reading through
// loop::RecordingEncoder, as the daemon records them; recorder limits from `k`; the log's time
// span into `span` when given. Errors name `source`, the line and the field.
Result<std::vector<calib::CountSegment>> read_count_segments(std::istream& in,
                                                             const std::string& source,
                                                             const Kinematics& k, int bits,
                                                             LogSpan* span = nullptr);

// Standard deviations for fixes whose sigma fields are empty.
struct FixDefaults {
  double sigma_xy = 0.005;         // [m]
  double sigma_theta = 0.0087266;  // [rad] (0.5 deg)
};

// read_fixes: CSV `t,x,y,theta,sigma_xy,sigma_theta` (t [s] on the log's clock, strictly
// increasing; theta [rad] in [-2 pi, 2 pi] (beyond: refused as degrees), empty = heading unknown;
// sigma_xy in (0, 10] m and sigma_theta in (0, 3.15] rad, empty = `d`). Errors name `source`, the
// line, the field and its range.
Result<std::vector<calib::PoseFix>> read_fixes(std::istream& in, const std::string& source,
                                               const FixDefaults& d = {});

// ---- The simulated LabMate of issue 18 (sim_selfcal, odomctl selfcal simulate) ----

inline constexpr double kSelfCalDn = 0.15;  // nominal wheel diameter [m]
inline constexpr double kSelfCalBn = 0.34;  // nominal wheelbase [m]

// selfcal_truth: the true absolute factors of sim::labmate_geometry: c = D_true / Dn per wheel
// (Eq. 6.35) and b = 0.337 m.
calib::Factors selfcal_truth();
// selfcal_kinematics: the LabMate's nominal kinematics (Dn 0.15 m, Ce 2048, n 16) with f.
Kinematics selfcal_kinematics(const calib::Factors& f);
// random_excursion: two to four random pieces (turns on the spot, straights, arcs), then turn
// towards the dock (origin), drive there and turn back to heading 0 (planned from the true
// pose, as any planner would). Wheel speeds as the robot commands them (nominal geometry).
sim::Scenario random_excursion(std::mt19937_64& rng, const Pose2& start);
// selfcal_e_max_syst: UMBmark E_max,syst [m] of the LabMate using f: `runs` cw + `runs` ccw
// 4 m squares (floor seeds floor_seed .. floor_seed + 2 runs - 1; rough: the report's floor),
// return error = true pose - odometry. runs = 5 is the report's measurement; on the rough floor
// its centres of gravity still carry the floor's random error (BENCHMARKS.md, issue 18: a
// calibration 0.05 mm apart in b scores 5 to 18 mm), so comparisons of calibrations use many
// runs (e.g. 200), which leaves the systematic error the report means.
double selfcal_e_max_syst(const calib::Factors& f, bool rough, int runs = 5,
                          std::uint64_t floor_seed = 500);

// SelfCalFitPoint: one completed fit of the estimator during `odomctl selfcal simulate`.
struct SelfCalFitPoint {
  int excursions = 0;             // excursions driven when the fit ran
  calib::Factors estimate;        // c_L, c_R [-], b [m]
  std::array<double, 3> sigma{};  // their standard deviations [-, -, m]
  bool applied = false;           // accepted and posted to the loop
};

// selfcal_svg: the convergence plot: relative error [%] of c_L, c_R and b against `truth`
// after each fit, with 1-sigma bars, filled markers for applied fits and open ones for the
// rest; `notes` (e.g. E_max,syst before and after) as text lines under the plot.
std::string selfcal_svg(const std::vector<SelfCalFitPoint>& fits, const calib::Factors& truth,
                        const std::vector<std::string>& notes, const std::string& title);

// ---- Fixes taken anywhere (issue 34): a robot of random geometry, Chong-Kleeman wheel noise ----

// SelfCalScenario: `odomctl selfcal simulate --scenario`: the LabMate's dock excursions through
// the daemon (issue 18) or open excursions of a random robot with a fix where each ends.
enum class SelfCalScenario : std::uint8_t { kDock, kOpen };
inline constexpr Choice<SelfCalScenario> kSelfCalScenarios[] = {{SelfCalScenario::kDock, "dock"},
                                                                {SelfCalScenario::kOpen, "open"}};

// FixDriveOptions: a drive of excursions, each ending with the robot still for 0.5 s and a fix
// of its true pose at the middle of the stop.
struct FixDriveOptions {
  int excursions = 20;
  bool dock = false;                   // true: excursions return to the dock (random_excursion);
                                       // false: open, 4-9 pieces (straights, arcs, spins)
  double sigma_xy = 0.005;             // fix noise [m]
  double sigma_theta = 0.0087266;      // [rad] (0.5 deg)
  double outliers = 0.0;               // fraction of fixes (not the first) moved 0.5-5 m
  double max_factor_error = 0.006;     // c_L, c_R uniform in 1 +- this ...
  double max_wheelbase_error = 0.015;  // ... and b in b_n (1 +- this), independently
  // > 0: c_L, c_R ~ N(1, prior_sigma_factor^2), b ~ N(b_n, prior_sigma_wheelbase^2) instead (the
  // truth drawn from the estimator's prior: what a coverage test of a dock drive needs, since
  // there the scale's uncertainty is the prior's).
  double prior_sigma_factor = 0.0;
  double prior_sigma_wheelbase = 0.0;  // [m]
  bool direct_drive = false;           // encoder on the wheel: 4096 counts/rev, no gear (else
                                       // 2048 counts/rev through a 16:1 gear)
  ErrorModelParams wheel_noise{};      // the true robot's k_L, k_R [m^(1/2)]
  std::uint64_t seed = 1;
  // kSkid4 (issue 38): the Jackal-sized skid-steer base of sim::jackal_skid_params instead of a
  // random LabMate: wheels as built (c_L = c_R = 1), the track the friction model decides, the
  // robot believing the geometric track x kSkidTrackMultiplier; open excursions only (dock false).
  UmbmarkRobot robot = UmbmarkRobot::kLabmate;
  // kSkid4: the centre of mass this far ahead of the geometric centre [m] (|.| < 0.131; 0: the
  // load centred, x_ICR 0): the friction model then turns the body about a point x_ICR ahead.
  double com_x = 0.0;
};

// A count log row at 100 Hz: `t,left,right` as `odomctl replay` / `calib fit-fixes` read it.
struct CountRow {
  double t = 0.0;  // [s]
  std::int64_t left = 0, right = 0;
};

struct FixDrive {
  sim::RobotGeometry geometry;  // the true robot
  calib::Factors truth;         // its c_L = D_L / Dn, c_R = D_R / Dn, b [m]
  KinematicParams nominal;      // what the robot believes (factors 1, b_n)
  std::vector<CountRow> ticks;
  std::vector<calib::CountSegment> segments;  // the ticks through the loop's recorder
  std::vector<calib::PoseFix> fixes;
  std::vector<Pose2> true_poses;  // at every fix
  std::vector<bool> corrupted;    // per fix
  // kSkid4: the drive's spot turns from the truth, sum |d_right - d_left| rim travel [m] over
  // sum |turned angle| [rad] (their ratio: the track the friction model gave those turns), and
  // friction solves that did not converge.
  double spot_turn_rim = 0.0, spot_turn_angle = 0.0;
  std::uint64_t unconverged = 0;
  // kSkid4: the friction model's x_ICR in a spot turn, -vy / omega of the solved twist for rims
  // -+0.2 m/s (what the fit's x_ICR is compared with) [m].
  double truth_x_icr = 0.0;
};

// simulate_fix_drive: the drive of `o` (repeatable for a seed). With robot kSkid4 the truth's b
// is the friction model's spot-turn track (equal to its arcs' with the load centred).
FixDrive simulate_fix_drive(const FixDriveOptions& o);

// fix_drive_config: the estimator's configuration for a drive: nominal values in use, the
// drive's wheel noise, prior and bounds of `base`; kSkid4 fits x_ICR (IcrFit::kFit, from 0).
calib::SelfCalConfig fix_drive_config(const FixDrive& d, const FixDriveOptions& o,
                                      calib::SelfCalConfig base = {});

// write_count_log / write_fixes: the CSV files `calib fit-fixes` reads (full precision).
std::string count_log_csv(const std::vector<CountRow>& rows);
std::string fixes_csv(const std::vector<calib::PoseFix>& fixes);

// ReferenceFit: the exact-model Gauss-Newton of issue 34 (maximum likelihood, no prior): the
// unknowns are p = (c_L, c_R, b) and the true pose at every fix; the residuals are every fix
// against its pose (its sigmas) and every excursion's end pose against the exact arcs from its
// start pose (Chong-Kleeman covariance), Jacobians by central differences. Written apart from
// calib::fit_fixes (no shared code but arc_step and the error model) as its yardstick.
struct ReferenceFit {
  calib::Factors estimate;
  calib::ParamCov covariance{};
  int iterations = 0;
  double last_step = 0.0;  // largest |step| of p in the last iteration
};
// reference_fit: over the fixes `use` marks (all when empty); excursions between used fixes.
ReferenceFit reference_fit(const calib::FixTrack& t, const calib::SelfCalConfig& c,
                           const std::vector<bool>& use = {});

}  // namespace odo::analysis
