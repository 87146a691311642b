// Calibration JSON formats and applying a stored record to the kinematics.
#include <gtest/gtest.h>

#include <atomic>
#include <nlohmann/json.hpp>

#include "calib_record_test_util.hpp"
#include "odo/analysis/calibration_json.hpp"
#include "odo/calibration/store.hpp"
#include "odo/firmware/calibration_reload.hpp"
#include "odo/firmware/calibration_store.hpp"
#include "odo/firmware/config.hpp"
#include "odo/loop/loop.hpp"
#include "odo/sim/sim_run.hpp"

namespace odo::fw {
namespace {

using calib::CalibrationRecord;
using calib::LoadResult;
using calib::StoreStatus;

KinematicParams nominal() {
  KinematicParams p;
  p.wheel_diameter = 0.15;
  p.counts_per_rev = 2048;
  p.gear_ratio = 16;
  p.wheelbase_nominal = p.wheelbase = 0.34;
  return p;
}

TEST(CalibrationIo, ImportsUmbmarkComputeOutput) {
  // The keys `odomctl umbmark compute --json` prints; unknown ones (alpha, beta, ...) ignored.
  const char* text =
      R"({"c_l":0.99925,"c_r":1.00075,"b_new":0.33702,"e_max_syst":0.232,"n_cw":5,"n_ccw":5,
          "alpha":0.0012,"beta":-0.0004,"e_d":1.0015,"e_b":0.9912})";
  auto r = analysis::parse_calibration_json(text, "u.json", 1795000000);
  ASSERT_TRUE(r) << r.error().message;
  EXPECT_DOUBLE_EQ(r->c_l, 0.99925);
  EXPECT_DOUBLE_EQ(r->c_r, 1.00075);
  ASSERT_TRUE(r->wheelbase);
  EXPECT_DOUBLE_EQ(*r->wheelbase, 0.33702);
  ASSERT_TRUE(r->e_max_before);
  EXPECT_DOUBLE_EQ(*r->e_max_before, 0.232);
  EXPECT_EQ(r->runs, 10U);  // 5 cw + 5 ccw
  EXPECT_EQ(r->method, "umbmark");
  EXPECT_EQ(r->time, 1795000000);
  EXPECT_FALSE(r->wheel_diameter);
}

TEST(CalibrationIo, ExportImportRoundTrip) {
  CalibrationRecord r;
  r.sequence = 7;
  r.c_l = 0.998;
  r.c_r = 1.002;
  r.wheelbase = 0.337;
  r.wheel_diameter = 0.1502;
  r.e_s = 0.9987;
  r.time = 1790000000;
  r.method = "umbmark";
  r.e_max_before = 0.3;
  r.e_max_after = 0.02;
  r.runs = 10;
  auto back = analysis::parse_calibration_json(analysis::export_json(r), "e.json", 0);
  ASSERT_TRUE(back) << back.error().message;
  r.sequence = 0;  // the store assigns sequence numbers; import does not carry them
  EXPECT_EQ(*back, r);
}

TEST(CalibrationIo, ExportImportCarriesTheIcrOffset) {
  // A skid-steer record (version 3): x_icr and its sigma survive export and import; without
  // them the export has no such keys (two-wheel exports as before).
  CalibrationRecord r = calib::test::umbmark_record();
  r.x_icr = 0.0309;
  r.sigma_x_icr = 0.0016;
  auto back = analysis::parse_calibration_json(analysis::export_json(r), "e.json", 0);
  ASSERT_TRUE(back) << back.error().message;
  EXPECT_EQ(*back, r);
  r.x_icr.reset();
  r.sigma_x_icr = 0.0;
  EXPECT_EQ(analysis::export_json(r).find("x_icr"), std::string::npos);
}

TEST(CalibrationIo, BadInputNamesTheField) {
  auto r = analysis::parse_calibration_json(R"({"c_l":1.3,"c_r":1.0})", "x.json", 0);
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().message.find("x.json"), std::string::npos);
  EXPECT_NE(r.error().message.find("c_l"), std::string::npos);
  EXPECT_NE(r.error().message.find("[0.9, 1.1]"), std::string::npos);
  r = analysis::parse_calibration_json(R"({"c_l":"one","c_r":1.0})", "x.json", 0);
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().message.find("field c_l: expected a number"), std::string::npos);
  r = analysis::parse_calibration_json(R"({"c_l":1.0})", "x.json", 0);
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().message.find("c_r is missing"), std::string::npos);
  r = analysis::parse_calibration_json(R"({"c_l":1.0,"c_r":1.0,"b_new":-0.3})", "x.json", 0);
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().message.find("wheelbase"), std::string::npos);
  EXPECT_FALSE(analysis::parse_calibration_json("{not json", "x.json", 0));
  EXPECT_FALSE(analysis::parse_calibration_json("[1,2]", "x.json", 0));
  r = analysis::parse_calibration_json(R"({"status":"corrupt","c_l":null,"c_r":null})", "s.json",
                                       0);
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().message.find("corrupt"), std::string::npos);
}

TEST(CalibrationIo, ShowJsonHasTheRequiredKeys) {
  LoadResult l;
  l.status = StoreStatus::kOk;
  CalibrationRecord r;
  r.sequence = 4;
  r.c_l = 0.999;
  r.c_r = 1.001;
  r.wheelbase = 0.337;
  l.record = r;
  l.slot = 1;
  auto j = nlohmann::json::parse(analysis::show_json(l));
  EXPECT_EQ(j["status"], "ok");
  EXPECT_EQ(j["sequence"], 4);
  EXPECT_EQ(j["c_l"], 0.999);
  EXPECT_EQ(j["c_r"], 1.001);
  EXPECT_EQ(j["wheelbase"], 0.337);
  EXPECT_TRUE(j["wheel_diameter"].is_null());
  LoadResult bad;
  bad.status = StoreStatus::kCorrupt;
  j = nlohmann::json::parse(analysis::show_json(bad));
  EXPECT_EQ(j["status"], "corrupt");
  EXPECT_TRUE(j["c_l"].is_null());  // no made-up values for a corrupt store
}

TEST(CalibrationIo, ApplyUsesStoredValuesOnlyWhenOk) {
  LoadResult l;
  l.status = StoreStatus::kOk;
  CalibrationRecord r;
  r.sequence = 2;
  r.c_l = 0.999;
  r.c_r = 1.001;
  r.wheelbase = 0.337;
  l.record = r;
  AppliedCalibration a = apply_calibration(nominal(), Result<LoadResult>(l), "test");
  EXPECT_EQ(a.state, calib::StoreStatus::kOk);
  EXPECT_EQ(a.sequence, 2U);
  EXPECT_DOUBLE_EQ(a.params.c_l, 0.999);
  EXPECT_DOUBLE_EQ(a.params.wheelbase, 0.337);
  EXPECT_DOUBLE_EQ(a.params.wheelbase_nominal, 0.34);
  EXPECT_DOUBLE_EQ(a.params.wheel_diameter, 0.15);  // not stored: nominal kept

  l.status = StoreStatus::kCorrupt;
  l.record.reset();
  a = apply_calibration(nominal(), Result<LoadResult>(l), "test");
  EXPECT_EQ(a.state, calib::StoreStatus::kCorrupt);
  EXPECT_DOUBLE_EQ(a.params.c_l, 1.0);
  EXPECT_NE(a.report.find("ERROR"), std::string::npos);
  EXPECT_NE(a.report.find("NOMINAL"), std::string::npos);

  a = apply_calibration(nominal(), Result<LoadResult>(make_error(Errc::kIo, "EACCES")), "test");
  EXPECT_EQ(a.state, calib::StoreStatus::kCorrupt);

  l.status = StoreStatus::kUncalibrated;
  a = apply_calibration(nominal(), Result<LoadResult>(l), "test");
  EXPECT_EQ(a.state, calib::StoreStatus::kUncalibrated);
  EXPECT_NE(a.report.find("nominal values"), std::string::npos);
}

TEST(CalibrationHandover, AppliedOnTheLoopThreadBetweenTicks) {
  // The loop stamps the store's status of its kinematics on every snapshot; kinematics posted
  // as a command are taken at the top of the next tick and the state changes with them.
  auto k = Kinematics::create(nominal());
  ASSERT_TRUE(k);
  auto run = sim::SimRun::create(sim::labmate_geometry(), *k, {{10.0, 1.0, 1.0}});
  ASSERT_TRUE(run);
  loop::OdometryLoop& l = (*run)->loop();
  l.start();
  l.tick();
  EXPECT_EQ(l.snapshot().calibration_state, StoreStatus::kUncalibrated);
  ASSERT_TRUE(l.post(loop::SetKinematics{*k, StoreStatus::kOk}));
  EXPECT_EQ(l.commands_applied(), 0U);
  l.tick();
  EXPECT_EQ(l.snapshot().calibration_state, StoreStatus::kOk);
  EXPECT_EQ(l.commands_applied(), 1U);
  ASSERT_TRUE(l.post(loop::SetKinematics{*k, StoreStatus::kCorrupt}));
  for (std::size_t i = 1; i < loop::CommandQueue::kCapacity; ++i)
    ASSERT_TRUE(l.post(loop::SetPose{l.snapshot().pose}));
  EXPECT_FALSE(l.post(loop::SetPose{}));  // queue full: the loop has not ticked
  l.tick();
  EXPECT_EQ(l.snapshot().calibration_state, StoreStatus::kCorrupt);
  EXPECT_EQ(l.commands_applied(), 1U + loop::CommandQueue::kCapacity);
}

}  // namespace
}  // namespace odo::fw

namespace odo::fw {
namespace {

TEST(CalibrationConfig, SectionKeysAndErrors) {
  auto c = parse_config("[calibration]\nstore = \"/dev/mtd3\"\nbackend = \"mtd\"\n", "t.toml");
  ASSERT_TRUE(c) << c.error().message;
  EXPECT_EQ(c->calibration.store, "/dev/mtd3");
  EXPECT_EQ(c->calibration.backend, NvBackend::kMtd);
  EXPECT_EQ(default_config().calibration.store, kDefaultCalibrationStore);
  auto bad = parse_config("[calibration]\nbackend = \"eeprom\"\n", "t.toml");
  ASSERT_FALSE(bad);
  EXPECT_NE(bad.error().message.find("backend"), std::string::npos);
  EXPECT_FALSE(parse_config("[calibration]\nstroe = \"x\"\n", "t.toml"));
}

TEST(CalibrationConfig, NoStoreConfiguredMeansNominal) {
  KinematicParams p;
  p.wheel_diameter = 0.15;
  p.counts_per_rev = 2048;
  p.wheelbase_nominal = p.wheelbase = 0.34;
  AppliedCalibration a = read_and_apply(p, "", NvBackend::kAuto);
  EXPECT_EQ(a.state, calib::StoreStatus::kUncalibrated);
  EXPECT_NE(a.report.find("no store configured"), std::string::npos);
}

}  // namespace
}  // namespace odo::fw
