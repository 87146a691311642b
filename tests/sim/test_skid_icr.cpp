// Where the plain effective-track model of a skid-steer base stops holding, and whether the ICR
// model of Mandow et al. 2007 fixes it (issue 38, item 3). The truth is the friction model of
// sim::SkidSteerBody (Jackal-sized base, README "Skid-steer bases"); the drives are 60 mixed open
// excursions (spot turns, straights, arcs of 0.5-2 m) as a self-calibration drive has them; each
// model's parameters are the best fit to the excursions' true end poses (what exact fixes give).
// The figures these bounds guard are BENCHMARKS.md's (issue 38, "effective track vs ICR").
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>

#include "odo/analysis/skid_tools.hpp"
#include "odo/odometry/pose.hpp"

namespace odo {
namespace {

using analysis::IcrParams;

constexpr double kSpeed = 0.2;  // [m/s]

// excursions: the same 60 mixed excursions for every floor and load (commanded with the guessed
// track 1.5 t).
const std::vector<analysis::RimExcursion>& excursions() {
  static const std::vector<analysis::RimExcursion> ex = [] {
    std::mt19937_64 rng(1);
    std::vector<analysis::RimExcursion> v;
    for (int i = 0; i < 60; ++i)
      v.push_back(analysis::mixed_excursion(rng, 1.5 * sim::jackal_skid_params().track));
    return v;
  }();
  return ex;
}

sim::SkidSteerParams base(double mu_ratio, double com_x) {
  sim::SkidSteerParams p = sim::jackal_skid_params();
  p.mu_lat = mu_ratio * p.mu_long;
  p.com_x = com_x;
  return p;
}

// arc_icr: the friction model's ICRs on a steady arc of commanded radius r [m] (0: spot turn),
// the rims those of a robot believing the geometric track.
IcrParams arc_icr(const sim::SkidSteerParams& p, double r) {
  const double c = 0.5 * p.track;
  const double vl = r > 0.0 ? kSpeed * (r - c) / r : -kSpeed;
  const double vr = r > 0.0 ? kSpeed * (r + c) / r : kSpeed;
  const sim::SkidSolution s = sim::solve_skid_twist(p, vl, vr);
  EXPECT_TRUE(s.converged);
  return analysis::icr_of(s.twist, vl, vr);
}

double track(const IcrParams& k) {
  return k.y_left - k.y_right;
}

TEST(SkidIcr, IcrModelWithCentredIcrsIsTheEffectiveTrack) {
  // B = 0.5 m, rims 0.1 and 0.3 m/s: omega = 0.2 / 0.5 = 0.4 rad/s, vx = (0.3 * 0.25 + 0.1 *
  // 0.25) / 0.5 = 0.2 m/s (the rims' mean), vy = 0; with x_icr = 0.05 m, vy = 0.05 * (0.1 -
  // 0.3) / 0.5 = -0.02 m/s (the centre slides outwards behind an ICR ahead of it).
  const sim::BodyTwist q = analysis::icr_twist({0.25, -0.25, 0.0}, 0.1, 0.3);
  EXPECT_DOUBLE_EQ(q.omega, 0.4);
  EXPECT_DOUBLE_EQ(q.vx, 0.2);
  EXPECT_DOUBLE_EQ(q.vy, 0.0);
  const sim::BodyTwist s = analysis::icr_twist({0.25, -0.25, 0.05}, 0.1, 0.3);
  EXPECT_DOUBLE_EQ(s.vy, -0.02);
  const IcrParams back = analysis::icr_of(s, 0.1, 0.3);  // the inverse
  EXPECT_NEAR(back.y_left, 0.25, 1e-15);
  EXPECT_NEAR(back.y_right, -0.25, 1e-15);
  EXPECT_NEAR(back.x_icr, 0.05, 1e-15);
}

TEST(SkidIcr, LoadCentredTrackHoldsOnEveryRadiusAndFloor) {
  // With the load centred all four wheels slip alike (test_umbmark_skid4), so the track is the
  // spot turn's t (1 + (mu_lat a / (mu_long c))^2) on every arc and floor, the ICRs sit on the
  // lateral axis, and the plain model is exact on the mixed drives.
  for (const double ratio : {0.5, 1.0, 1.25}) {
    SCOPED_TRACE("mu_lat / mu_long " + std::to_string(ratio));
    const sim::SkidSteerParams p = base(ratio, 0.0);
    const double a = p.half_wheelbase, c = 0.5 * p.track;
    const double closed = p.track * (1.0 + std::pow(ratio * a / c, 2));
    for (const double r : {0.0, 0.5, 1.0, 2.0, 5.0, 50.0}) {
      const IcrParams k = arc_icr(p, r);
      EXPECT_NEAR(track(k) / closed, 1.0, 1e-6) << "radius " << r;
      EXPECT_NEAR(k.x_icr, 0.0, 1e-9) << "radius " << r;
    }
    const analysis::SkidModelFit f = analysis::fit_skid_models(p, excursions());
    EXPECT_EQ(f.unconverged, 0U);
    EXPECT_LT(f.rms_spot, 1e-6);
    EXPECT_NEAR(f.track / closed, 1.0, 1e-6);
  }
}

TEST(SkidIcr, OffsetLoadNeedsTheLongitudinalIcrOffset) {
  // The load 10 or 20 mm forward (8 or 15 % of a), rubber on a hard floor (mu_lat = mu_long):
  // the heavier front axle resists sliding, the body turns about a point x_icr ahead (about 3x
  // the offset) and its centre slides sideways by 2 x_icr sin(dtheta / 2) in each turn. The
  // track changes little with the radius of realistic arcs (< 1 % from the spot turn to 2 m),
  // so the best single track cannot absorb the slide: the ICR model's x_icr is what reduces the
  // mixed drives' end-position error, by far more than the 2x; the lateral offsets
  // left free (Mandow's three parameters) add nothing to the symmetric pair (B, x_icr).
  for (const double com : {0.01, 0.02}) {
    SCOPED_TRACE("com_x " + std::to_string(com));
    const sim::SkidSteerParams p = base(1.0, com);
    const IcrParams spot = arc_icr(p, 0.0);
    EXPECT_GT(spot.x_icr, 2.5 * com);
    EXPECT_LT(std::fabs(track(arc_icr(p, 2.0)) / track(spot) - 1.0), 0.01);
    const analysis::SkidModelFit f = analysis::fit_skid_models(p, excursions());
    EXPECT_EQ(f.unconverged, 0U);
    EXPECT_GT(f.rms_track / f.rms_icr_sym, 4.0)
        << "track " << f.rms_track << " m, ICR " << f.rms_icr_sym << " m";
    EXPECT_NEAR(f.icr_sym.x_icr / spot.x_icr, 1.0, 0.02);  // exact fixes see the spot turn's
    EXPECT_GT(f.rms_icr / f.rms_icr_sym, 0.99);
    const std::string tag = std::to_string(static_cast<int>(std::lround(com * 1e3))) + "mm";
    RecordProperty("rms_track_mm_com" + tag, std::to_string(f.rms_track * 1e3));
    RecordProperty("rms_icr_mm_com" + tag, std::to_string(f.rms_icr_sym * 1e3));
    RecordProperty("x_icr_mm_com" + tag, std::to_string(f.icr_sym.x_icr * 1e3));
  }
}

TEST(SkidIcr, FrontAxleStickingDefeatsBothModels) {
  // The load 40 mm forward: the front wheels stop sliding sideways in a spot turn (x_icr -> a,
  // the body pivots about its front axle, the track falls to about the geometric one) while on
  // wide arcs both axles slide again: the track depends on the radius and no constant
  // parameters describe the base (neither model reaches 2x; both leave decimetres).
  const sim::SkidSteerParams p = base(1.0, 0.04);
  const IcrParams spot = arc_icr(p, 0.0);
  EXPECT_NEAR(spot.x_icr / p.half_wheelbase, 1.0, 0.02);
  EXPECT_LT(track(spot) / p.track, 1.02);
  EXPECT_GT(track(arc_icr(p, 50.0)) / track(spot), 1.3);
  const analysis::SkidModelFit f = analysis::fit_skid_models(p, excursions());
  EXPECT_EQ(f.unconverged, 0U);
  EXPECT_LT(f.rms_track / f.rms_icr_sym, 2.0);
  EXPECT_GT(f.rms_icr_sym, 0.1);
}

TEST(SkidIcr, UmbmarkSquareCannotSeeTheIcrOffset) {
  // A square's four equal spot turns slide the centre by the same body-frame vector, seen in
  // four headings 90 deg apart: the slides cancel, so the return error (UMBmark's measurement)
  // is blind to x_icr. Pieces: 4 m legs at 0.2 m/s, 90 deg spot turns, both directions.
  const IcrParams plain{0.2571, -0.2571, 0.0}, icr{0.2571, -0.2571, 0.0644};
  for (const double sense : {1.0, -1.0}) {
    Pose2 a, b;
    for (int leg = 0; leg < 4; ++leg) {
      const double turn = std::numbers::pi / 2.0 * track(plain) / (2.0 * kSpeed);  // [s]
      for (const analysis::RimPiece& r :
           {analysis::RimPiece{4.0 / kSpeed, kSpeed, kSpeed},
            analysis::RimPiece{turn, -sense * kSpeed, sense * kSpeed}}) {
        a = sim::twist_step(a, analysis::icr_twist(plain, r.v_left, r.v_right), r.duration);
        b = sim::twist_step(b, analysis::icr_twist(icr, r.v_left, r.v_right), r.duration);
      }
    }
    EXPECT_NEAR(b.x - a.x, 0.0, 1e-9);
    EXPECT_NEAR(b.y - a.y, 0.0, 1e-9);
    EXPECT_NEAR(std::remainder(b.theta - a.theta, 2.0 * std::numbers::pi), 0.0, 1e-12);
  }
}

// product_rms: rms end-position error [m] over the excursions of the firmware's own Odometry
// with wheelbase b [m] and x_icr [m], fed each piece's rim travels in ticks of at most 1 ms,
// against the friction model's end poses.
double product_rms(const sim::SkidSteerParams& p, double b, double x_icr) {
  KinematicParams kp{0.15, 2048, 16, b, b, 1.0, 1.0};
  kp.x_icr = x_icr;
  const Kinematics k = *Kinematics::create(kp);
  double sum = 0.0;
  for (const analysis::RimExcursion& e : excursions()) {
    Pose2 truth;
    Odometry o(k);
    for (const analysis::RimPiece& r : e) {
      truth =
          sim::twist_step(truth, sim::solve_skid_twist(p, r.v_left, r.v_right).twist, r.duration);
      const int n = static_cast<int>(std::ceil(r.duration / 1e-3));
      const double dt = r.duration / n;
      for (int i = 0; i < n; ++i) o.update_travel(r.v_left * dt, r.v_right * dt, dt);
    }
    sum += std::pow(o.pose().x - truth.x, 2) + std::pow(o.pose().y - truth.y, 2);
  }
  return std::sqrt(sum / static_cast<double>(excursions().size()));
}

TEST(SkidIcr, FirmwareOdometryWithXIcrIsTheFittedIcrModel) {
  // The load 10 mm forward: the firmware's Odometry with [robot] x_icr and wheelbase set to the
  // fitted symmetric ICR pair ends where that model does (the same constant-twist steps, cut
  // into 1 ms ticks: exact arcs compose), so it inherits the pair's gain over the best single
  // track, which the plain Odometry (x_icr = 0) reproduces in turn.
  const sim::SkidSteerParams p = base(1.0, 0.01);
  const analysis::SkidModelFit f = analysis::fit_skid_models(p, excursions());
  const double plain = product_rms(p, f.track, 0.0);
  const double icr = product_rms(p, track(f.icr_sym), f.icr_sym.x_icr);
  EXPECT_NEAR(plain, f.rms_track, 1e-6 + 1e-3 * f.rms_track);
  EXPECT_NEAR(icr, f.rms_icr_sym, 1e-6 + 1e-3 * f.rms_icr_sym);
  EXPECT_GT(plain / icr, 4.0) << "plain " << plain << " m, with x_icr " << icr << " m";
  RecordProperty("rms_plain_mm", std::to_string(1e3 * plain));
  RecordProperty("rms_x_icr_mm", std::to_string(1e3 * icr));
  RecordProperty("x_icr_mm", std::to_string(1e3 * f.icr_sym.x_icr));
}

}  // namespace
}  // namespace odo
