// Does a skid-steer base need more than an effective track (issue 38, item 3)? The friction
// model of sim::SkidSteerBody drives mixed excursions; odometry with the best single effective
// track and odometry with the best instantaneous-centre-of-rotation (ICR) model of Mandow et al.
// 2007 ("Experimental kinematics for wheeled skid-steer mobile robots", IROS 2007) are fitted to
// the same end poses and their errors compared (README "Skid-steer bases", BENCHMARKS.md).
#pragma once

#include <cstdint>
#include <random>
#include <vector>

#include "odo/odometry/pose.hpp"
#include "odo/sim/skid_steer.hpp"

namespace odo::analysis {

// IcrParams: the ICR kinematics. y_left, y_right [m]: lateral positions of the left and right
// wheels' instantaneous centres of rotation (y left, y_left > y_right); x_icr [m]: the
// longitudinal position of the body's ICR ahead of the geometric centre. With B = y_left -
// y_right (the effective track) and rim speeds v_L, v_R:
//   vx = (v_R y_left - v_L y_right) / B,  vy = x_icr (v_L - v_R) / B,  omega = (v_R - v_L) / B.
// y_left = -y_right = B/2, x_icr = 0 is the plain effective-track model.
struct IcrParams {
  double y_left = 0.0;
  double y_right = 0.0;
  double x_icr = 0.0;
};

// icr_twist: the body twist of the ICR model for rim speeds v_left, v_right [m/s].
sim::BodyTwist icr_twist(const IcrParams& k, double v_left, double v_right) noexcept;
// icr_of: the ICRs of a solved twist q for rim speeds v_left, v_right [m/s] (the inverse of
// icr_twist): y_left = (vx - v_L) / omega, y_right = (vx - v_R) / omega, x_icr = -vy / omega;
// all 0 when omega == 0.
IcrParams icr_of(const sim::BodyTwist& q, double v_left, double v_right) noexcept;

// RimPiece: constant rim speeds [m/s] for a duration [s].
struct RimPiece {
  double duration = 0.0;
  double v_left = 0.0, v_right = 0.0;
};
using RimExcursion = std::vector<RimPiece>;

// mixed_excursion: 4 to 9 pieces as an open self-calibration drive has them (spot turns of
// 0.3-3 rad at 0.5 rad/s, straights of 1-4 m and arcs of radius 0.5-2 m over 0.8-2.4 rad at
// 0.2 m/s), rim speeds commanded with the believed track `track` [m].
RimExcursion mixed_excursion(std::mt19937_64& rng, double track);

// SkidModelFit: the best models over a set of excursions and their end-pose errors.
struct SkidModelFit {
  double track = 0.0;        // best single effective track [m]
  IcrParams icr_sym;         // best symmetric ICRs (y_left = -y_right) and x_icr [m]
  IcrParams icr;             // best ICR parameters, all three free [m]
  double rms_track = 0.0;    // rms end-position error per excursion, effective track [m]
  double rms_icr_sym = 0.0;  // ... symmetric ICR model [m]
  double rms_icr = 0.0;      // ... ICR model [m]
  double rms_spot = 0.0;     // ... effective track = the spot turn's (what UMBmark finds) [m]
  IcrParams spot;            // the friction model's ICRs in a spot turn (rims +-0.2 m/s) [m]
  std::uint64_t unconverged = 0;
};

// fit_skid_models: every excursion starts at the origin; the truth moves with the friction model
// p (exact integration of each piece's solved twist), each model with its own twist; the best
// parameters minimise the sum over excursions of |end-position error|^2 + (1 m x heading
// error)^2 (Gauss-Newton, central differences). p must pass sim::check_skid_params.
SkidModelFit fit_skid_models(const sim::SkidSteerParams& p,
                             const std::vector<RimExcursion>& excursions);

}  // namespace odo::analysis
