// UMBmark on the simulated skid-steer base (issue 38): the robot starts from Clearpath's guess
// (geometric track x 1.5); one pass must find the track the friction model produces in the
// square's spot turns within 2 % and shrink the square's return error at least 10x.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>

#include "odo/analysis/umbmark_tools.hpp"
#include "odo/sim/sim_run.hpp"
#include "odo/sim/skid_steer.hpp"

namespace odo::test {
namespace {

analysis::UmbmarkSimResult simulate_skid4(int runs) {
  analysis::UmbmarkSimOptions o;
  o.robot = analysis::UmbmarkRobot::kSkid4;
  o.runs = runs;
  auto r = analysis::run_umbmark_simulation(o);
  EXPECT_TRUE(r.ok()) << (r.ok() ? "" : r.error().message);
  return r.ok() ? std::move(r).value() : analysis::UmbmarkSimResult{};
}

TEST(UmbmarkSkid4, GeometricTrackOdometryOverestimatesTheSpotTurn) {
  // The skid body through the same SimRun path as the LabMate (SimEncoderSource, the loop at its
  // default rate): a spot turn whose rims each travel d = (pi/2) t / 2 makes odometry with the
  // geometric track t report 90 deg, while the body turns only 2d / B = (pi/2) t / B with
  // B = 0.5583531 m (unit_skid_steer): 90 deg / 1.486603 = 60.54 deg, about its own centre.
  const sim::RobotGeometry g = sim::skid4_geometry();
  auto believed = Kinematics::create(sim::nominal_params(0.196, g.wheelbase, g));
  ASSERT_TRUE(believed.ok());
  auto body = sim::SkidSteerBody::create(sim::jackal_skid_params());
  ASSERT_TRUE(body.ok());
  const double pi = std::numbers::pi, d = pi / 2.0 * g.wheelbase / 2.0, duration = 2.0;
  const double w = d / 0.098 / duration;  // [rad/s] of each wheel
  sim::SimRunOptions ro;
  ro.skid = &*body;
  auto run = sim::SimRun::create(g, *believed, {{duration, -w, w}}, ro);
  ASSERT_TRUE(run.ok());
  (*run)->drive(0.5);
  const Pose2 odo = (*run)->loop().odometry().pose();
  const Pose2 truth = (*run)->robot().true_pose();
  EXPECT_NEAR(odo.theta, pi / 2.0, 1e-3);  // whole encoder counts
  EXPECT_NEAR(truth.theta, pi / 2.0 * g.wheelbase / 0.5583531, 1e-6);
  EXPECT_NEAR(truth.x, 0.0, 1e-12);
  EXPECT_NEAR(truth.y, 0.0, 1e-12);
  EXPECT_EQ(body->unconverged(), 0U);
}

TEST(UmbmarkSkid4, OnePassFindsTheFrictionModelsTrackAndImprovesTenfold) {
  const auto r = simulate_skid4(1);  // noiseless runs are identical: one a direction
  ASSERT_EQ(r.passes.size(), 1U);
  ASSERT_TRUE(r.skid.has_value());
  const analysis::SkidTrackReport& k = *r.skid;
  EXPECT_EQ(k.unconverged, 0U);
  EXPECT_DOUBLE_EQ(k.geometric, 0.37559);
  EXPECT_DOUBLE_EQ(k.guessed, 1.5 * 0.37559);
  EXPECT_DOUBLE_EQ(r.passes[0].before.factors.wheelbase, k.guessed);
  // The spot turns' track comes from the friction model, not from the odometry's formula: the
  // symmetric spot turn's closed form t (1 + (a/c)^2) = 0.5583531 m (unit_skid_steer).
  EXPECT_NEAR(k.spot_turn, 0.5583531, 1e-6);
  EXPECT_LT(std::fabs(k.found - k.spot_turn) / k.spot_turn, 0.02)
      << "found " << k.found << " m, friction model " << k.spot_turn << " m";
  const double before = r.passes[0].before.e_max_syst, after = r.passes[0].after.e_max_syst;
  EXPECT_GE(before / after, 10.0) << "before " << before << " m, after " << after << " m";
  RecordProperty("found_track_mm", std::to_string(k.found * 1e3));
  RecordProperty("spot_turn_track_mm", std::to_string(k.spot_turn * 1e3));
  RecordProperty("e_max_before_mm", std::to_string(before * 1e3));
  RecordProperty("e_max_after_mm", std::to_string(after * 1e3));
}

TEST(UmbmarkSkid4, ArcTrackHoldsOnlyWithTheLoadCentred) {
  // Centre of mass at the geometric centre: the twist (vx = (vL + vR)/2, vy = 0, omega) gives all
  // four wheels slips of equal size (|sx| = |vR - vL| |1/2 - c/B|, |sy| = omega a), so the
  // Coulomb law acts as a linear one and the track of the spot turn holds on every arc. With the
  // load 2 cm forward the axles' loads differ, the centre slides sideways and the track grows
  // from the spot turn's towards the large arcs': the plain effective-track model stops holding.
  const auto r = simulate_skid4(1);
  ASSERT_TRUE(r.skid.has_value());
  const analysis::SkidTrackReport& k = *r.skid;
  const std::size_t n = std::size(analysis::kSkidArcRadii);
  ASSERT_EQ(k.arcs.size(), 2 * n);
  EXPECT_EQ(k.unconverged, 0U);
  for (std::size_t i = 0; i < n; ++i) {
    EXPECT_NEAR(k.arcs[i].track, k.spot_turn, 1e-6) << k.arcs[i].radius;
    EXPECT_DOUBLE_EQ(k.arcs[n + i].com_x, analysis::kSkidComOffset);
    if (i > 0) {
      EXPECT_GT(k.arcs[n + i].track, k.arcs[n + i - 1].track) << k.arcs[n + i].radius;
    }
  }
  // Spot turn vs a 50 m arc with the load forward: more than 5 % apart.
  EXPECT_GT(k.arcs[2 * n - 1].track / k.arcs[n].track, 1.05);
  RecordProperty("offset_spot_track_mm", std::to_string(k.arcs[n].track * 1e3));
  RecordProperty("offset_arc50_track_mm", std::to_string(k.arcs[2 * n - 1].track * 1e3));
}

}  // namespace
}  // namespace odo::test
