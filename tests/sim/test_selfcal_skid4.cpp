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

}  // namespace
}  // namespace odo
