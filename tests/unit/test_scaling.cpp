#include <gtest/gtest.h>

#include "odo/calibration/scaling.hpp"

namespace odo::calib {
namespace {

TEST(Scaling, LargerWheelNeedsLargerDiameter) {
  // Odometry says 3.000 m, the tape says 3.012 m: E_s = 3.000 / 3.012 = 0.996016 (Eq. B.1).
  // The wheel is really Dn / E_s = 0.15 * 3.012 / 3.000 = 0.15060 m.
  auto r = scaling_error(3.000, 3.012, 0.15);
  ASSERT_TRUE(r.ok());
  EXPECT_NEAR(r->e_s, 3.000 / 3.012, 1e-15);
  EXPECT_NEAR(r->wheel_diameter_new, 0.1506, 1e-15);
}

TEST(Scaling, RejectsNonsense) {
  EXPECT_FALSE(scaling_error(0.0, 3.0, 0.15).ok());
  EXPECT_FALSE(scaling_error(3.0, -1.0, 0.15).ok());
  EXPECT_FALSE(scaling_error(3.0, 3.0, 0.0).ok());
  // 3 m against 3000 (mm by mistake): E_s = 0.001, outside [0.8, 1.25].
  auto r = scaling_error(3.0, 3000.0, 0.15);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().message.find("E_s"), std::string::npos);
}

}  // namespace
}  // namespace odo::calib
