// Offline self-calibration input (`odomctl calib fit-fixes`, issue 18): a replay count log
// recorded into segments by the loop's own recorder, and a CSV of absolute fixes.
#pragma once

#include <array>
#include <cstdint>
#include <istream>
#include <random>
#include <string>
#include <vector>

#include "odo/calibration/count_recorder.hpp"
#include "odo/calibration/selfcal.hpp"
#include "odo/hal/result.hpp"
#include "odo/odometry/kinematics.hpp"
#include "odo/odometry/pose.hpp"
#include "odo/sim/robot.hpp"

namespace odo::analysis {

// read_count_segments: the replay log `t,left,right` (optionally `gyro_z`, not used yet; t [s]
// non-decreasing, raw `bits`-wide readings) passed reading by reading through
// loop::RecordingEncoder, as the daemon records them; recorder limits from `k`. Errors name
// `source`, the line and the field.
Result<std::vector<calib::CountSegment>> read_count_segments(std::istream& in,
                                                             const std::string& source,
                                                             const Kinematics& k, int bits);

// Standard deviations for fixes whose sigma fields are empty.
struct FixDefaults {
  double sigma_xy = 0.005;         // [m]
  double sigma_theta = 0.0087266;  // [rad] (0.5 deg)
};

// read_fixes: CSV `t,x,y,theta,sigma_xy,sigma_theta` (t [s] on the log's clock, strictly
// increasing; theta [rad] empty = heading unknown; sigma_xy in (0, 10] m and sigma_theta in
// (0, 3.15] rad, empty = `d`). Errors name `source`, the line, the field and its range.
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

}  // namespace odo::analysis
