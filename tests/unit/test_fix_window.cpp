// calibration/fix_window: the online self-calibration's window policy (issue 18; a unit of its
// own since issue 33). Times in seconds below are written in ns through s().
#include "odo/calibration/fix_window.hpp"

#include <gtest/gtest.h>

namespace odo::calib {
namespace {

constexpr TimeNs s(double seconds) {
  return static_cast<TimeNs>(seconds * 1e9);
}

PoseFix fix_at(double t) {
  PoseFix f;
  f.t = s(t);
  f.sigma_xy = 0.01;
  return f;
}

CountSegment seg(double t0, double t1) {
  return {s(t0), s(t1), 10, 10};
}

FixWindow::Policy policy() {
  // ripe_delay 0.5 s: a fix at t is taken once the record reaches t + 0.5 s.
  return {4, 3, 2, s(0.5)};
}

TEST(FixWindow, FixesEnterInTimeOrderOnceTheirCountsAreRecorded) {
  FixWindow w(policy());
  w.add_fix(fix_at(10.2));
  w.add_fix(fix_at(10.0));  // out of order: sorted before it is taken
  w.add_fix(fix_at(11.0));
  // Record up to 10.8 s: 10.0 + 0.5 and 10.2 + 0.5 <= 10.8, 11.0 + 0.5 is not.
  EXPECT_EQ(w.take_ripe(s(10.8)), 0u);
  ASSERT_EQ(w.fixes().size(), 2u);
  EXPECT_EQ(w.fixes()[0].t, s(10.0));
  EXPECT_EQ(w.fixes()[1].t, s(10.2));
  EXPECT_EQ(w.pending_count(), 1u);
  // A late fix older than the window's newest is dropped; 11.0 is now ripe.
  w.add_fix(fix_at(10.1));
  EXPECT_EQ(w.take_ripe(s(11.5)), 1u);
  ASSERT_EQ(w.fixes().size(), 3u);
  EXPECT_EQ(w.fixes()[2].t, s(11.0));
}

TEST(FixWindow, WithoutAWindowAFixOlderThanTheKeptCountsIsDropped) {
  FixWindow w(policy());
  // Record at 20 s: counts are kept from 20 - 5 = 15 s; a fix at 14.9 s lost those after it.
  w.add_fix(fix_at(14.9));
  w.add_fix(fix_at(15.1));
  EXPECT_EQ(w.take_ripe(s(20.0)), 1u);
  ASSERT_EQ(w.fixes().size(), 1u);
  EXPECT_EQ(w.fixes()[0].t, s(15.1));
}

TEST(FixWindow, TrimKeepsMaxFixesAndTheCountsFromTheFirstFix) {
  FixWindow w(policy());
  for (double t = 0.0; t < 12.0; t += 1.0) w.add_segment(seg(t, t + 1.0));  // 0-12 s
  // Without a fix: the segments ending at or before 12 - 5 = 7 s go.
  w.trim(s(12.0));
  EXPECT_EQ(w.segment_count(), 5u);  // ending at 8, 9, 10, 11, 12 s
  for (double t : {7.5, 8.5, 9.5, 10.5, 11.5}) w.add_fix(fix_at(t));
  w.take_ripe(s(12.0));
  // Five fixes, four kept (7.5 goes); counts before 8.5 s go: the segment ending at 8 s.
  w.trim(s(12.0));
  ASSERT_EQ(w.fixes().size(), 4u);
  EXPECT_EQ(w.fixes().front().t, s(8.5));
  EXPECT_EQ(w.segment_count(), 4u);
  EXPECT_EQ(w.segments().front().t_end, s(9.0));
}

TEST(FixWindow, AFitIsDueAfterMinFixesThenEveryFitEveryNewOnes) {
  // Record at 6 s: fixes from 6 - 5 = 1 s on are taken into an empty window.
  FixWindow w(policy());  // min_fixes 3, fit_every 2
  w.add_fix(fix_at(1.0));
  w.add_fix(fix_at(2.0));
  w.take_ripe(s(6.0));
  EXPECT_FALSE(w.fit_due());  // 2 fixes < 3
  w.add_fix(fix_at(3.0));
  w.take_ripe(s(6.0));
  EXPECT_TRUE(w.fit_due());   // 3 fixes, 3 new >= 2
  EXPECT_FALSE(w.fit_due());  // 0 new since
  w.add_fix(fix_at(4.0));
  w.take_ripe(s(6.0));
  EXPECT_FALSE(w.fit_due());  // 1 new
  w.add_fix(fix_at(5.0));
  w.take_ripe(s(6.0));
  EXPECT_TRUE(w.fit_due());  // 2 new
}

TEST(FixWindow, RejectedFixesCountOnceAndAnAcceptedFitStartsAtTheNewest) {
  FixWindow w(policy());
  for (double t : {1.0, 2.0, 3.0}) w.add_fix(fix_at(t));
  w.take_ripe(s(6.0));
  EXPECT_EQ(w.newly_rejected({0, 2}), 2u);
  EXPECT_EQ(w.newly_rejected({0, 1, 2}), 1u);  // only fix 1 is new
  EXPECT_EQ(w.newly_rejected({7}), 0u);        // not in the window: ignored
  w.restart_at_newest();
  ASSERT_EQ(w.fixes().size(), 1u);
  EXPECT_EQ(w.fixes()[0].t, s(3.0));
  EXPECT_EQ(w.newly_rejected({0}), 1u);  // the kept fix counts afresh in the new window
}

}  // namespace
}  // namespace odo::calib
