// SimRobot: a differential-drive base whose true geometry may differ from what the firmware
// believes. It is driven by wheel angular velocities, keeps the exact ground-truth pose, and
// produces encoder counts the way a quadrature encoder does (whole quadrature states only).
#pragma once

#include <cstdint>
#include <limits>
#include <vector>

#include "odo/hal/result.hpp"
#include "odo/hal/time.hpp"
#include "odo/odometry/kinematics.hpp"
#include "odo/odometry/pose.hpp"

namespace odo::sim {

class SkidSteerBody;

// True physical geometry of the simulated base.
struct RobotGeometry {
  double wheel_diameter_left = 0.15;   // [m]
  double wheel_diameter_right = 0.15;  // [m]
  double wheelbase = 0.34;             // [m], distance between the wheel contact points
  double counts_per_rev = 2048;        // encoder counts per motor revolution after 4x decoding
  double gear_ratio = 16;              // motor revolutions per wheel revolution
};

// One piece of a motion profile: constant wheel angular velocities for a duration.
struct Segment {
  double duration = 0.0;     // [s]
  double omega_left = 0.0;   // wheel angular velocity [rad/s], positive drives forward
  double omega_right = 0.0;  // [rad/s]
};

using Scenario = std::vector<Segment>;

// labmate_geometry: the reference robot of the UMBmark report's SET simulation: true wheelbase
// 337 mm (nominal 340 mm) and wheel diameter ratio D_R/D_L = 0.9985 at the nominal mean diameter.
RobotGeometry labmate_geometry(double nominal_diameter = 0.15);

// nominal_params: the firmware's belief for a robot with this encoder/gear set-up.
KinematicParams nominal_params(double wheel_diameter, double wheelbase, const RobotGeometry& g);

enum class Turn { kClockwise, kCounterClockwise };

// TravelPerturbation: changes what the wheels really travel over the ground during one simulation
// step (slip, non-systematic noise); the encoders still count the wheel rotation.
class TravelPerturbation {
 public:
  virtual ~TravelPerturbation() = default;
  // perturb: d_left, d_right [m] are the ground travels of this step; change them in place.
  virtual void perturb(double& d_left, double& d_right) noexcept = 0;
};

// SquareOptions: the UMBmark square path.
struct SquareOptions {
  double side = 4.0;       // leg length [m]
  double speed = 0.2;      // leg speed [m/s]
  double turn_rate = 0.5;  // on-the-spot turn rate [rad/s]
  double pause = 0.5;      // standstill after every leg and every turn [s]
  Turn direction = Turn::kCounterClockwise;
};

// square_scenario: the wheel-velocity profile with which a robot that believes `believed`
// drives an UMBmark square: every leg and every 90 degree turn is a whole number of encoder
// counts sized so that the robot's own odometry (with its factors c_L, c_R and wheelbase b)
// sees the nominal path.
Scenario square_scenario(const Kinematics& believed, const SquareOptions& o);

// SquareSet: the squares a simulated run drives one after the other (odometryd's [sim] scenario,
// also the microcontroller firmware's run in QEMU: both compose their robot with these).
enum class SquareSet : std::uint8_t { kNone, kCcw, kCw, kBoth };

// squares_scenario: the squares of `set` (counter-clockwise first), each with square_scenario's
// options `o` (its direction ignored); kNone: an empty scenario (the robot stands still).
Scenario squares_scenario(const Kinematics& believed, SquareOptions o, SquareSet set);

// simulated_geometry: the true geometry of a simulated robot with the belief `p`: the LabMate's
// errors (labmate_geometry with p's diameter) or, labmate false, exactly the belief.
RobotGeometry simulated_geometry(bool labmate, const KinematicParams& p);

// scenario_duration: total duration of a scenario [s].
double scenario_duration(const Scenario& s);

class SimRobot {
 public:
  // Position of the encoder disc inside its quadrature state at start, in counts [0, 1).
  static constexpr double kEncoderPhase = 0.5;

  // create: validates the geometry (positive, finite) and starts at `start` with zero counts.
  static Result<SimRobot> create(const RobotGeometry& g, Scenario scenario,
                                 const Pose2& start = {});

  // advance_to: move the robot along its scenario up to time t [ns since start]; after the last
  // segment it stands still. Never goes backwards.
  void advance_to(TimeNs t) noexcept {
    // Inline common case (one encoder read per tick): a single step inside the current segment.
    if (t > t_ && t < seg_end_) {
      move(to_seconds(t - t_), scenario_[seg_]);
      t_ = t;
      return;
    }
    advance_across(t);
  }

  const Pose2& true_pose() const noexcept { return pose_; }
  // counts_left/right: cumulative encoder counts, floor of the motor angle in counts. The count
  // changes only when the shaft crosses a quadrature state boundary; the encoder starts half a
  // state away from one (kEncoderPhase), as a real disc rests somewhere inside a state.
  std::int64_t counts_left() const noexcept {
    return floor_to_int(angle_l_ * counts_per_wheel_rad_ + kEncoderPhase);
  }
  std::int64_t counts_right() const noexcept {
    return floor_to_int(angle_r_ * counts_per_wheel_rad_ + kEncoderPhase);
  }
  double wheel_angle_left() const noexcept { return angle_l_; }   // [rad] of the wheel
  double wheel_angle_right() const noexcept { return angle_r_; }  // [rad]
  TimeNs time() const noexcept { return t_; }
  bool finished() const noexcept { return seg_ >= scenario_.size(); }
  const RobotGeometry& geometry() const noexcept { return g_; }
  const Scenario& scenario() const noexcept { return scenario_; }
  // set_travel_perturbation: applied to every step's ground travel (not owned; null = none).
  void set_travel_perturbation(TravelPerturbation* p) noexcept { perturbation_ = p; }
  // set_skid_body: move as this skid-steer body (its friction decides the twist from the rim
  // travels) instead of the differential-drive arc of wheelbase g.wheelbase (not owned; null =
  // the arc). The encoders still count the wheel rotation.
  void set_skid_body(SkidSteerBody* b) noexcept { skid_ = b; }

 private:
  SimRobot(const RobotGeometry& g, Scenario s, const Pose2& start);
  // floor_to_int: floor(v) as an integer for |v| < 2^63 (std::floor is a library call at -O2
  // on baseline x86-64; truncation plus a correction for negative fractions is inline).
  static std::int64_t floor_to_int(double v) noexcept {
    const auto i = static_cast<std::int64_t>(v);
    return i - (static_cast<double>(i) > v ? 1 : 0);
  }
  void move(double dt, const Segment& seg) noexcept;
  // advance_across: advance_to for steps that reach a segment end or lie past the scenario.
  void advance_across(TimeNs t) noexcept;

  RobotGeometry g_;
  Scenario scenario_;
  std::size_t seg_ = 0;
  TimeNs seg_start_ = 0;  // start time of segment seg_ [ns]
  // End time of segment seg_ [ns], computed once per segment; kNoSegment after the last one.
  static constexpr TimeNs kNoSegment = std::numeric_limits<TimeNs>::min();
  TimeNs seg_end_ = kNoSegment;
  TimeNs t_ = 0;
  Pose2 pose_;
  HeadingRotor heading_;  // of pose_.theta, re-derived every kResyncSteps (robot.cpp)
  // Half-angle rotation of the last step, reused while the step's travels are bit-identical
  // (constant wheel speeds and step length); NaN keys never match, so the first step computes.
  double step_d_l_ = std::numeric_limits<double>::quiet_NaN();  // [m] key: left travel
  double step_d_r_ = std::numeric_limits<double>::quiet_NaN();  // [m] key: right travel
  double step_sin_h_ = 0.0;                                     // sin(h), h = half the turn
  double step_cos_h_ = 1.0;                                     // cos(h)
  double step_chord_ = 0.0;  // [m] chord of the step, ds * sin(h)/h
  double step_dth_ = 0.0;    // [rad] heading change of the step, 2h
  double angle_l_ = 0.0;
  double angle_r_ = 0.0;
  double counts_per_wheel_rad_ = 0.0;
  TravelPerturbation* perturbation_ = nullptr;
  SkidSteerBody* skid_ = nullptr;
};

}  // namespace odo::sim
