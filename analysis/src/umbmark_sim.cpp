// The automated UMBmark self-calibration on the simulated robot, with the firmware's loop.
#include <atomic>
#include <cmath>
#include <random>
#include <sstream>

#include "odo/analysis/seed.hpp"
#include "odo/analysis/umbmark_tools.hpp"
#include "odo/hal/field_range.hpp"
#include "odo/odometry/gyrodometry.hpp"
#include "odo/sim/floor.hpp"
#include "odo/sim/robot.hpp"
#include "odo/sim/sim_gyro.hpp"
#include "odo/sim/sim_run.hpp"
#include "odo/sim/skid_steer.hpp"

namespace odo::analysis {
namespace {

using calib::Direction;
using calib::Factors;
using calib::UmbmarkRun;

constexpr double kNominalDiameter = 0.15;   // [m] Dn of the simulated LabMate
constexpr double kNominalWheelbase = 0.34;  // [m] what the uncalibrated LabMate believes

// SimBase: the robot of --robot: its true geometry, the belief the first set starts from and,
// for a skid-steer base, the friction model its body moves with.
struct SimBase {
  sim::RobotGeometry truth;
  double diameter = 0.0;   // [m] nominal wheel diameter the robot believes
  double wheelbase = 0.0;  // [m] wheelbase the uncalibrated robot believes
  std::optional<sim::SkidSteerParams> skid;
};

SimBase sim_base(UmbmarkRobot r) {
  if (r == UmbmarkRobot::kSkid4) {
    const sim::RobotGeometry g = sim::skid4_geometry();
    // The uncalibrated skid-steer base believes the published guess: geometric track x 1.5.
    return SimBase{g, g.wheel_diameter_left, kSkidTrackMultiplier * g.wheelbase,
                   sim::jackal_skid_params()};
  }
  return SimBase{sim::labmate_geometry(kNominalDiameter), kNominalDiameter, kNominalWheelbase, {}};
}

struct Driver {
  const UmbmarkSimOptions& o;
  SimBase base;
  std::uint64_t run_index = 0;  // every run draws its own random sequences
  int done = 0, total = 0;
  const std::function<void(int, int)>& progress;
  const sim::GyroModel* gyro = nullptr;     // the fused squares' gyro (--gyro); null: plain
  bool exact_reference = false;             // no reference-sensor error (gyro comparison)
  std::uint64_t events = 0;                 // flagged intervals of the fused squares
  double turn_rim = 0.0, turn_angle = 0.0;  // skid body: spot turns' rim travel [m], angle [rad]
  std::uint64_t unconverged = 0;            // skid body: friction solves that did not converge

  // believed: the kinematics of the robot driving with factors f.
  Result<Kinematics> believed(const Factors& f) const {
    KinematicParams p = sim::nominal_params(base.diameter, base.wheelbase, base.truth);
    p.wheelbase = f.wheelbase;
    p.c_l = f.c_l;
    p.c_r = f.c_r;
    return Kinematics::create(p);
  }

  // floor_options: the floor under one square in direction d (roughness, bumps).
  sim::UmbmarkFloor::Options floor_options(Direction d, bool bumps) const {
    sim::UmbmarkFloor::Options fo;
    fo.wheel_radius = base.diameter / 2.0;
    fo.roughness_height = o.noise == UmbmarkNoise::kPaper ? kPaperRoughness : 0.0;
    fo.bumps = bumps ? 10 : 0;
    fo.bump_loss = kBumpLoss;
    fo.first_leg = o.side;
    fo.bumps_under_left = d == Direction::kCcw;  // the wheel facing the inside of the square
    return fo;
  }

  // square: one square in direction d with factors f; the return error truth - odometry in the
  // start frame (which is the odometry frame: both start at the origin, heading 0).
  Result<UmbmarkRun> square(const Factors& f, Direction d, bool bumps) {
    auto k = believed(f);
    if (!k) return std::move(k).error();
    sim::SquareOptions so;
    so.side = o.side;
    so.direction = d == Direction::kCw ? sim::Turn::kClockwise : sim::Turn::kCounterClockwise;
    const bool paper = o.noise == UmbmarkNoise::kPaper;
    const std::uint64_t seed = seed_of(o.seed, run_index++);
    sim::UmbmarkFloor floor(floor_options(d, bumps), seed);
    sim::SimRunOptions ro;
    ro.perturbation = &floor;
    ro.gyro = gyro;
    ro.gyro_seed = seed ^ 0x6E0ULL;
    std::optional<sim::SkidSteerBody> body;
    if (base.skid) {
      auto b = sim::SkidSteerBody::create(*base.skid);
      if (!b) return std::move(b).error();
      body.emplace(std::move(b).value());
      ro.skid = &*body;
    }
    auto run = sim::SimRun::create(base.truth, *k, sim::square_scenario(*k, so), ro);
    if (!run) return std::move(run).error();
    // One second of standstill after the path: the last readings see the robot stopped.
    (*run)->drive(1.0);
    if (body) {
      turn_rim += body->spot_turn_rim();
      turn_angle += body->spot_turn_angle();
      unconverged += body->unconverged();
    }
    if (const Gyrodometry* g = (*run)->loop().fusion()) {
      const FusionCounters& c = g->counters();
      events += c.disagreements + c.speed_events + c.accel_events;
    }
    const Pose2 e = (*run)->error();
    UmbmarkRun r;
    r.direction = d;
    r.bumps = bumps;
    r.ex = e.x;
    r.ey = e.y;
    r.etheta = e.theta;
    if (paper && !exact_reference) {
      // The reference ("sonar calibrator") measures the absolute pose with its own error.
      std::mt19937_64 rng(seed ^ 0x5EC0ADULL);
      std::normal_distribution<double> n01(0.0, 1.0);
      r.ex += kReferenceSigmaXy * n01(rng);
      r.ey += kReferenceSigmaXy * n01(rng);
      *r.etheta += kReferenceSigmaTheta * n01(rng);
    }
    if (progress) progress(++done, total);
    return r;
  }

  // set: N cw and N ccw squares with factors f.
  Result<UmbmarkRunSet> set(const Factors& f, bool bumps) {
    UmbmarkRunSet s;
    s.factors = f;
    for (Direction d : {Direction::kCw, Direction::kCcw}) {
      for (int i = 0; i < o.runs; ++i) {
        auto r = square(f, d, bumps);
        if (!r) return std::move(r).error();
        s.runs.push_back(*r);
      }
    }
    s.cw = calib::centre_of_gravity(s.runs, Direction::kCw);
    s.ccw = calib::centre_of_gravity(s.runs, Direction::kCcw);
    s.e_max_syst = calib::e_max_syst(s.cw, s.ccw);
    s.spread = calib::set_spread(s.runs, s.cw, s.ccw);
    return s;
  }
};

// mean_position_error: mean |(ex, ey)| over the runs [m].
double mean_position_error(const std::vector<UmbmarkRun>& runs) {
  double sum = 0.0;
  for (const UmbmarkRun& r : runs) sum += std::hypot(r.ex, r.ey);
  return runs.empty() ? 0.0 : sum / static_cast<double>(runs.size());
}

// gyro_comparison: the --gyro sets. Each pair of sets starts at the same run index, so plain and
// fused squares see the same seeds (floor, bumps); the reference is exact throughout.
Result<UmbmarkGyroComparison> gyro_comparison(Driver& drv, const Factors& uncal, const Factors& cal,
                                              const sim::GyroModel& model) {
  const auto n = static_cast<std::uint64_t>(2 * drv.o.runs);
  const std::uint64_t base = drv.run_index;  // smooth: base, bumps: base + n, calibrated: + 2n
  drv.exact_reference = true;
  UmbmarkGyroComparison c;
  auto pair = [&](const Factors& f, bool bumps, std::uint64_t at,
                  const sim::GyroModel* g) -> Result<UmbmarkRunSet> {
    drv.run_index = at;
    drv.gyro = g;
    return drv.set(f, bumps);
  };
  std::vector<UmbmarkRun> plain, fused;
  for (const bool bumps : {false, true}) {
    auto p = pair(uncal, bumps, base + (bumps ? n : 0), nullptr);
    if (!p) return std::move(p).error();
    auto f = pair(uncal, bumps, base + (bumps ? n : 0), &model);
    if (!f) return std::move(f).error();
    plain.insert(plain.end(), p->runs.begin(), p->runs.end());
    fused.insert(fused.end(), f->runs.begin(), f->runs.end());
    if (bumps) c.uncal_plain_bumps = mean_position_error(p->runs);
  }
  auto ep = calib::eps_theta_nonsys(plain);
  if (!ep) return std::move(ep).error();
  auto ef = calib::eps_theta_nonsys(fused);
  if (!ef) return std::move(ef).error();
  c.eps_plain = *ep;
  c.eps_fused = *ef;
  auto cal_bumps = pair(cal, true, base + n, &model);
  if (!cal_bumps) return std::move(cal_bumps).error();
  c.cal_fused_bumps = mean_position_error(cal_bumps->runs);
  auto cal_plain = pair(cal, false, base + 2 * n, nullptr);
  if (!cal_plain) return std::move(cal_plain).error();
  auto cal_fused = pair(cal, false, base + 2 * n, &model);
  if (!cal_fused) return std::move(cal_fused).error();
  c.cal_plain_smooth = mean_position_error(cal_plain->runs);
  c.cal_fused_smooth = mean_position_error(cal_fused->runs);
  c.events = drv.events;
  drv.gyro = nullptr;
  drv.exact_reference = false;
  return c;
}

// skid_report: the effective tracks of --robot skid4: UMBmark's b against the guess, the spot
// turns' track from the truth, and steady arcs of growing radius from the same friction model.
SkidTrackReport skid_report(const Driver& drv, double found) {
  const sim::SkidSteerParams& p = *drv.base.skid;
  SkidTrackReport r;
  r.geometric = p.track;
  r.guessed = kSkidTrackMultiplier * p.track;
  r.found = found;
  r.spot_turn = drv.turn_angle > 0.0 ? drv.turn_rim / drv.turn_angle : 0.0;
  r.unconverged = drv.unconverged;
  constexpr double kArcSpeed = 0.2;  // [m/s]
  for (const double com_x : {p.com_x, p.com_x + kSkidComOffset}) {
    sim::SkidSteerParams q = p;
    q.com_x = com_x;
    for (const double radius : kSkidArcRadii) {
      // The rim speeds a robot believing the geometric track commands for this arc.
      const double c = 0.5 * p.track;
      const double vl = radius > 0.0 ? kArcSpeed * (radius - c) / radius : -kArcSpeed;
      const double vr = radius > 0.0 ? kArcSpeed * (radius + c) / radius : kArcSpeed;
      const sim::SkidSolution s = sim::solve_skid_twist(q, vl, vr);
      if (!s.converged) ++r.unconverged;
      r.arcs.push_back({com_x, radius, std::hypot(s.twist.vx, s.twist.vy) / s.twist.omega,
                        sim::effective_track(s, vl, vr)});
    }
  }
  return r;
}

}  // namespace

std::ostream& operator<<(std::ostream& out, UmbmarkRobot r) {
  return out << choice_name(kUmbmarkRobots, r);
}

std::ostream& operator<<(std::ostream& out, UmbmarkNoise n) {
  return out << choice_name(kUmbmarkNoises, n);
}

Result<UmbmarkRobot> parse_umbmark_robot(std::string_view text) {
  if (auto r = choice_value<UmbmarkRobot>(kUmbmarkRobots, text)) return *r;
  return make_error(Errc::kInvalidArgument,
                    "--robot = '" + std::string(text) +
                        "' is not known (allowed: " + choice_join(kUmbmarkRobots, ", ") + ")");
}

Result<UmbmarkNoise> parse_umbmark_noise(std::string_view text) {
  return parse_choice_of<UmbmarkNoise>(kUmbmarkNoises, "--noise", text);
}

Status check_umbmark_sim_options(const UmbmarkSimOptions& o) {
  if (o.runs < 1 || o.runs > 1000) return range_error(integer_range("--runs", o.runs, 1, 1000));
  if (o.passes < 1 || o.passes > 10) return range_error(integer_range("--passes", o.passes, 1, 10));
  if (!(o.side >= 0.5 && o.side <= 20.0)) return range_error({"--side", o.side, 0.5, 20.0, "m"});
  return Ok{};
}

Result<UmbmarkSquares> score_umbmark_factors(const UmbmarkSimOptions& o, const calib::Factors& f) {
  if (auto s = check_umbmark_sim_options(o); !s) return std::move(s).error();
  const std::function<void(int, int)> none;
  Driver drv{o, sim_base(o.robot), 0, 0, 2 * o.runs, none};
  auto set = drv.set(f, false);
  if (!set) return std::move(set).error();
  return UmbmarkSquares{std::move(set).value(),
                        drv.turn_angle > 0.0 ? drv.turn_rim / drv.turn_angle : 0.0,
                        drv.unconverged};
}

Result<UmbmarkSimResult> run_umbmark_simulation(const UmbmarkSimOptions& o,
                                                const std::function<void(int, int)>& progress) {
  if (auto s = check_umbmark_sim_options(o); !s) return std::move(s).error();
  Driver drv{o, sim_base(o.robot), 0, 0, 0, progress};
  // Pass 1 drives a "before" set (plus the bump runs) and a verification; later passes reuse
  // the previous verification as their "before" set.
  drv.total =
      2 * o.runs * (1 + (o.bumps ? 1 : 0) + o.passes + (o.gyro != UmbmarkGyro::kNone ? 7 : 0));
  UmbmarkSimResult res;
  auto first = drv.set(Factors{1.0, 1.0, drv.base.wheelbase}, false);
  if (!first) return std::move(first).error();
  if (o.bumps) {
    auto b = drv.set(first->factors, true);
    if (!b) return std::move(b).error();
    res.bump_runs = std::move(b->runs);
  }
  UmbmarkRunSet before = std::move(first).value();
  for (int p = 0; p < o.passes; ++p) {
    calib::UmbmarkInput in;
    in.runs = before.runs;
    if (p == 0) in.runs.insert(in.runs.end(), res.bump_runs.begin(), res.bump_runs.end());
    in.side = o.side;
    in.current = before.factors;
    in.formula = o.formula;
    auto r = calib::umbmark_compute(in);
    if (!r) return std::move(r).error();
    auto after = drv.set(r->composed, false);
    if (!after) return std::move(after).error();
    res.passes.push_back(UmbmarkSimPass{std::move(before), std::move(r).value(), *after});
    before = std::move(after).value();
  }
  if (o.gyro != UmbmarkGyro::kNone) {
    const sim::GyroModel m =
        o.gyro == UmbmarkGyro::kIndustrial ? sim::industrial_gyro() : sim::consumer_gyro();
    auto g = gyro_comparison(drv, res.passes.front().before.factors,
                             res.passes.back().result.composed, m);
    if (!g) return std::move(g).error();
    res.gyro = *g;
  }
  if (drv.base.skid) res.skid = skid_report(drv, res.passes.back().result.composed.wheelbase);
  const double last = res.passes.back().after.e_max_syst;
  res.improvement = last > 0.0 ? res.passes.front().before.e_max_syst / last : 0.0;
  return res;
}

}  // namespace odo::analysis
