// Tools around the UMBmark calibration (odomctl umbmark): the CSV of measured return errors,
// the automated self-calibration on the simulated robot (through the firmware's own loop) and
// the SVG of the return errors before and after (like Fig. 3.4 / 6.5 of the report).
#pragma once

#include <cstdint>
#include <functional>
#include <istream>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "odo/calibration/umbmark.hpp"
#include "odo/hal/angle.hpp"
#include "odo/hal/choice.hpp"
#include "odo/hal/result.hpp"

namespace odo::analysis {

// read_umbmark_runs: the CSV of `umbmark compute`: header direction,ex,ey with optional
// etheta and bumps; direction cw|ccw, ex, ey [m] and etheta [rad] finite and within +-1000,
// bumps 0|1. Errors name source:line and the field.
Result<std::vector<calib::UmbmarkRun>> read_umbmark_runs(std::istream& in,
                                                         const std::string& source);

// UmbmarkRobot, UmbmarkNoise: choices of the UMBmark simulation, spelt once in their tables
// (odomctl --robot, --noise); printed with their spelling.
enum class UmbmarkRobot : std::uint8_t {
  kLabmate,  // the reference robot of DESIGN.md
  kSkid4,    // a Jackal-sized 4WD skid-steer base (sim::jackal_skid_params; README "Skid-steer")
};
enum class UmbmarkNoise : std::uint8_t {
  kNone,
  kPaper,  // floor roughness + reference-sensor error
};
// UmbmarkGyro: the simulated gyro also fused in a comparison run (--gyro).
enum class UmbmarkGyro : std::uint8_t { kNone, kConsumer, kIndustrial };
inline constexpr Choice<UmbmarkGyro> kUmbmarkGyros[] = {{UmbmarkGyro::kNone, "none"},
                                                        {UmbmarkGyro::kConsumer, "consumer"},
                                                        {UmbmarkGyro::kIndustrial, "industrial"}};
inline constexpr Choice<UmbmarkRobot> kUmbmarkRobots[] = {{UmbmarkRobot::kLabmate, "labmate"},
                                                          {UmbmarkRobot::kSkid4, "skid4"}};
inline constexpr Choice<UmbmarkNoise> kUmbmarkNoises[] = {{UmbmarkNoise::kNone, "none"},
                                                          {UmbmarkNoise::kPaper, "paper"}};
std::ostream& operator<<(std::ostream& out, UmbmarkRobot r);
std::ostream& operator<<(std::ostream& out, UmbmarkNoise n);
// parse_umbmark_robot, parse_umbmark_noise: the choice spelt `text`; the error names the
// option (--robot, --noise) and the choices.
Result<UmbmarkRobot> parse_umbmark_robot(std::string_view text);
Result<UmbmarkNoise> parse_umbmark_noise(std::string_view text);
// format_umbmark_runs: the CSV read_umbmark_runs() reads, header direction,ex,ey,etheta,bumps;
// ex, ey [m] with 4 decimals (0.1 mm, the CAN pose resolution), etheta [rad] with 5 (empty when
// not measured). What `umbmark simulate --csv` and `umbmark record` write.
std::string format_umbmark_runs(const std::vector<calib::UmbmarkRun>& runs);

struct UmbmarkSimOptions {
  UmbmarkRobot robot = UmbmarkRobot::kLabmate;
  int runs = 5;       // N squares a direction per set, 1 .. 1000
  int passes = 1;     // 1 .. 10
  double side = 4.0;  // L [m], 0.5 .. 20
  UmbmarkNoise noise = UmbmarkNoise::kNone;
  bool bumps = false;  // add N + N extended-UMBmark runs to the first pass
  std::uint64_t seed = 1;
  calib::WheelbaseFormula formula = calib::WheelbaseFormula::kUmbmark629;
  // --gyro: none | consumer | industrial: also drive the comparison with that simulated gyro
  // fused by the loop (UmbmarkGyroComparison).
  UmbmarkGyro gyro = UmbmarkGyro::kNone;
};

// The floor and reference of --noise paper (README "UMBmark calibration" shows the resulting
// sigma): roughness bumps every ~2 cm with heights uniform in [0, kPaperRoughness], the
// reference ("sonar calibrator") with standard deviations 2 mm and 0.4 deg.
inline constexpr double kPaperRoughness = 0.0013;          // [m]
inline constexpr double kReferenceSigmaXy = 0.002;         // [m]
inline constexpr double kReferenceSigmaTheta = 0.0069813;  // [rad] = 0.4 deg
// Travel loss of one extended-UMBmark bump: the report's 0.44 deg per 10 mm bump on a LabMate
// (Sec. 3.4) times the true wheelbase 0.337 m.
inline constexpr double kBumpLoss = 0.337 * 0.44 * kRadPerDeg;  // [m]

// One set of N + N runs driven with the given factors.
struct UmbmarkRunSet {
  calib::Factors factors;               // c_L, c_R, b [m] the robot used
  std::vector<calib::UmbmarkRun> runs;  // return errors (with etheta)
  calib::CentreOfGravity cw, ccw;
  double e_max_syst = 0.0;  // [m]
  calib::SetSpread spread;  // sigma, SEM and the 3 x SEM verdict of these runs
};

struct UmbmarkSimPass {
  UmbmarkRunSet before;         // the pass's input runs (pass > 1: the previous verification)
  calib::UmbmarkResult result;  // computed from `before` (plus bump runs in pass 1)
  UmbmarkRunSet after;          // verification with result.composed
};

// UmbmarkGyroComparison (--gyro): the same squares (same seeds, so the same floor) driven with
// odometry alone and with the gyro fused, every return error against the exact reference pose.
// "uncal": the factors the first pass started from; "cal": the last pass's result.
struct UmbmarkGyroComparison {
  std::optional<double> eps_plain, eps_fused;  // eps_theta,nonsys, uncalibrated, bumps [rad]
  double uncal_plain_bumps = 0.0;  // mean |(ex, ey)| on the bump course, uncalibrated, plain [m]
  double cal_fused_bumps = 0.0;    // ... calibrated and fused [m]
  double cal_plain_smooth = 0.0;   // mean |(ex, ey)| on the smooth course, calibrated, plain [m]
  double cal_fused_smooth = 0.0;   // ... calibrated and fused [m]
  std::uint64_t events = 0;        // flagged intervals started over all fused squares
};

// Multiplier of the geometric track in Clearpath's Jackal and Husky configs
// (wheel_separation_multiplier): the guess --robot skid4 starts from.
inline constexpr double kSkidTrackMultiplier = 1.5;

// SkidArcTrack: the effective track the skid body's friction model shows on one steady arc.
struct SkidArcTrack {
  double com_x = 0.0;        // [m] centre of mass ahead of the geometric centre
  double radius = 0.0;       // [m] of the commanded arc (geometric-track rim speeds); 0: spot
  double true_radius = 0.0;  // [m] |(vx, vy)| / omega: the geometric centre's true path radius
  double track = 0.0;        // [m] (v_right - v_left) / omega
};
// The arcs of SkidTrackReport: centre speed 0.2 m/s (the legs' speed; spot turns: rims at
// +-0.2 m/s), the base's own centre of mass and one kSkidComOffset ahead (a payload forward:
// where the plain effective-track model stops holding, README "Skid-steer bases").
inline constexpr double kSkidArcRadii[] = {0.0, 0.5, 1.0, 2.0, 5.0, 10.0, 50.0};  // [m]
inline constexpr double kSkidComOffset = 0.02;                                    // [m]

// SkidTrackReport (--robot skid4): the effective track UMBmark found against the guess and
// against what the simulator's friction model produces.
struct SkidTrackReport {
  double geometric = 0.0;  // t [m]
  double guessed = 0.0;    // kSkidTrackMultiplier * t [m], the first set's wheelbase
  double found = 0.0;      // b [m] of the last pass
  // The squares' on-the-spot turns, from the truth: sum |d_right - d_left| rim travel over sum
  // |turned angle| [m].
  double spot_turn = 0.0;
  std::vector<SkidArcTrack> arcs;  // steady arcs (kSkidArcRadii; com_x 0, kSkidComOffset)
  std::uint64_t unconverged = 0;   // friction solves that did not converge
};

struct UmbmarkSimResult {
  std::optional<SkidTrackReport> skid;        // with --robot skid4
  std::optional<UmbmarkGyroComparison> gyro;  // with --gyro
  std::vector<UmbmarkSimPass> passes;
  std::vector<calib::UmbmarkRun> bump_runs;  // extended UMBmark runs of pass 1 (--bumps)
  double improvement = 0.0;                  // first before / last after E_max,syst
};

// check_umbmark_sim_options: validates every field; the message names the option and its range.
Status check_umbmark_sim_options(const UmbmarkSimOptions& o);

// run_umbmark_simulation: the automated self-calibration on the simulated robot in virtual time.
// Every square is driven by the robot's own odometry with its current factors
// (sim::square_scenario) and integrated by loop::OdometryLoop; the return error is the reference
// pose (true pose, plus the reference's error with --noise paper) minus the loop's pose. Pass k's
// input is pass k-1's verification set (the compensated robot as a "new" robot).
// progress(done, total) after every run.
Result<UmbmarkSimResult> run_umbmark_simulation(const UmbmarkSimOptions& o,
                                                const std::function<void(int, int)>& progress = {});

// UmbmarkSquares: one set of squares driven with given factors (score_umbmark_factors).
struct UmbmarkSquares {
  UmbmarkRunSet set;
  double spot_turn = 0.0;  // skid-steer base: the squares' spot turns' track from the truth [m]
  std::uint64_t unconverged = 0;  // skid-steer base: friction solves that did not converge
};
// score_umbmark_factors: o.runs cw + o.runs ccw squares of o.side on o.robot with the factors f
// (c_L, c_R, b [m]), as run_umbmark_simulation drives its sets (floor and reference of o.noise,
// seeds from o.seed): how a calibration found elsewhere (e.g. from fixes) does on the square.
Result<UmbmarkSquares> score_umbmark_factors(const UmbmarkSimOptions& o, const calib::Factors& f);

// umbmark_svg: two ex-ey panels [mm], each on its own equal-scale frame with ticks and a grid:
// the first "before" set with its bump runs, and every pass's verification set (a marker shape
// of its own for each of up to 10 passes); cw and ccw, and the centres of gravity.
std::string umbmark_svg(const UmbmarkSimResult& r, const std::string& title);

}  // namespace odo::analysis
