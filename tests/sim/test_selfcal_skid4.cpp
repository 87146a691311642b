// Self-calibration from fixes on the simulated skid-steer base (issue 38, item 5): the Jackal-sized
// 4WD base (sim::jackal_skid_params) believes Clearpath's guess, the geometric track x 1.5, and
// drives 20 open excursions (spot turns, straights, arcs) with a 5 mm / 0.5 deg fix where each
// ends, as `odomctl selfcal simulate --robot skid4` does. The done means: the effective
// track found within 2 % of the one the friction model produces in the square's turns, and the
// square's return error at least 10x smaller than with the guess.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "odo/analysis/selfcal_tools.hpp"
#include "odo/analysis/umbmark_tools.hpp"
#include "odo/calibration/selfcal.hpp"
#include "odo/sim/skid_steer.hpp"

namespace odo {
namespace {

// Seeds of the drives (fix noise, wheel noise, excursions): three keep the test near 2 s.
constexpr std::uint64_t kSeeds[] = {1, 2, 3};

analysis::UmbmarkSquares squares(const calib::Factors& f) {
  analysis::UmbmarkSimOptions o;
  o.robot = analysis::UmbmarkRobot::kSkid4;
  o.runs = 1;  // noiseless squares are identical: one a direction
  auto r = analysis::score_umbmark_factors(o, f);
  EXPECT_TRUE(r.ok()) << (r.ok() ? "" : r.error().message);
  return r.ok() ? std::move(r).value() : analysis::UmbmarkSquares{};
}

TEST(SelfCalSkid4, FindsTheFrictionModelsTrackAndImprovesTheSquareTenfold) {
  const double t = sim::skid4_geometry().wheelbase;
  const analysis::UmbmarkSquares guess = squares({1.0, 1.0, analysis::kSkidTrackMultiplier * t});
  EXPECT_EQ(guess.unconverged, 0U);
  for (const std::uint64_t seed : kSeeds) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    analysis::FixDriveOptions fo;
    fo.robot = analysis::UmbmarkRobot::kSkid4;
    fo.seed = seed;
    const analysis::FixDrive d = analysis::simulate_fix_drive(fo);
    EXPECT_EQ(d.unconverged, 0U);
    EXPECT_DOUBLE_EQ(d.nominal.wheelbase, 1.5 * t);  // the robot starts from the guess
    ASSERT_GT(d.spot_turn_angle, 0.0);               // the drive has spot turns
    auto track = calib::build_track(d.segments, d.fixes);
    ASSERT_TRUE(track.ok()) << track.error().message;
    auto r = calib::fit_fixes(*track, analysis::fix_drive_config(d, fo));
    ASSERT_TRUE(r.ok()) << r.error().message;
    const double found = r->estimate.wheelbase;
    const analysis::UmbmarkSquares cal = squares(r->estimate);
    EXPECT_EQ(cal.unconverged, 0U);
    // The friction model's track in the square's spot turns, from the truth (rim travel over
    // turned angle), is the drive's own spot turns' and the truth the drive reports.
    EXPECT_NEAR(cal.spot_turn, d.spot_turn_rim / d.spot_turn_angle, 1e-6);
    EXPECT_NEAR(cal.spot_turn, d.truth.wheelbase, 1e-6);
    EXPECT_LT(std::fabs(found - cal.spot_turn) / cal.spot_turn, 0.02)
        << "found " << found << " m, friction model " << cal.spot_turn << " m";
    const double before = guess.set.e_max_syst, after = cal.set.e_max_syst;
    EXPECT_GE(before / after, 10.0) << "guess " << before << " m, self-calibrated " << after;
    RecordProperty("found_track_mm_seed" + std::to_string(seed), std::to_string(found * 1e3));
    RecordProperty("e_max_after_mm_seed" + std::to_string(seed), std::to_string(after * 1e3));
  }
  RecordProperty("e_max_guess_mm", std::to_string(guess.set.e_max_syst * 1e3));
}

// The load 10 mm ahead of the centre (mu_lat = mu_long): the friction model turns the body about
// a point x_ICR = 30.92 mm ahead in a spot turn (BENCHMARKS.md, "effective track against the ICR
// model"), and the fit, with x_ICR as its 4th parameter (fix_drive_config: IcrFit::kFit for
// skid4), finds it. Tolerance: 3 sigma of the fit's own x_ICR (1.6-1.9 mm from 20 excursions with
// 5 mm / 0.5 deg fixes: the fix noise, not the model) plus 2 % of the value (the friction
// model's x_ICR is not one constant: on the 0.5-2 m arcs of the drive it differs from the spot
// turn's by up to 2 % at this load, sim_skid_icr). Seeds 1-8 gave errors of -0.9 to +2.1 sigma
// (BENCHMARKS.md). The track stays within 2 % of the friction model's spot-turn track.
TEST(SelfCalSkid4, FindsTheIcrOffsetOfALoadAheadOfTheCentre) {
  for (const std::uint64_t seed : kSeeds) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    analysis::FixDriveOptions fo;
    fo.robot = analysis::UmbmarkRobot::kSkid4;
    fo.seed = seed;
    fo.com_x = 0.010;
    const analysis::FixDrive d = analysis::simulate_fix_drive(fo);
    EXPECT_EQ(d.unconverged, 0U);
    EXPECT_NEAR(d.truth_x_icr, 0.03092, 5e-5);  // BENCHMARKS.md's 30.9 mm
    auto track = calib::build_track(d.segments, d.fixes);
    ASSERT_TRUE(track.ok()) << track.error().message;
    const calib::SelfCalConfig c = analysis::fix_drive_config(d, fo);
    ASSERT_EQ(c.icr, calib::IcrFit::kFit);
    auto r = calib::fit_fixes(*track, c);
    ASSERT_TRUE(r.ok()) << r.error().message;
    EXPECT_TRUE(r->x_icr_observable) << "sigma " << r->sigma_x_icr;
    EXPECT_LT(r->sigma_x_icr, c.max_sigma_x_icr);
    EXPECT_LT(std::fabs(r->x_icr - d.truth_x_icr), 3.0 * r->sigma_x_icr + 0.02 * d.truth_x_icr)
        << "found " << r->x_icr << " m, friction model " << d.truth_x_icr << " m";
    EXPECT_LT(std::fabs(r->estimate.wheelbase - d.truth.wheelbase) / d.truth.wheelbase, 0.02);
    EXPECT_EQ(r->verdict, calib::Verdict::kAccepted);
    RecordProperty("x_icr_mm_seed" + std::to_string(seed), std::to_string(r->x_icr * 1e3));
  }
}

}  // namespace
}  // namespace odo
