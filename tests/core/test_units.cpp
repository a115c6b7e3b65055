// core/units.hpp: each constant is the correctly rounded value of the expression the code used
// before it existed (so that replacing a local constant by it changes no result), and the
// conversions agree with their definitions (1 deg = pi/180 rad, 1' = 1/60 deg, 1" = 1/3600 deg,
// 1 g = 9.80665 m/s^2).
#include "core/units.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace imscal {
namespace {

// Exact equality: the same double as the expressions written out in the files before.
static_assert(kRadPerDeg == M_PI / 180.0);
static_assert(kRadPerDeg == 3.14159265358979323846 / 180.0);
static_assert(kDegPerRad == 180.0 / M_PI);
static_assert(kRadPerArcsec == M_PI / (180.0 * 3600.0));
static_assert(kRadPerArcsec == M_PI / 180.0 / 3600.0);
static_assert(kRadPerArcmin == M_PI / 180.0 / 60.0);
static_assert(kArcminPerRad == 180.0 / M_PI * 60.0);
static_assert(kArcsecPerRad == 180.0 / M_PI * 3600.0);
static_assert(kStandardGravity_m_s2 == 9.80665);

TEST(Units, ConversionsAreInverseWithinRounding) {
  // Products of two correctly rounded reciprocals: within 2 ulp of 1.
  EXPECT_NEAR(kRadPerDeg * kDegPerRad, 1.0, 4.5e-16);
  EXPECT_NEAR(kRadPerArcmin * kArcminPerRad, 1.0, 4.5e-16);
  EXPECT_NEAR(kRadPerArcsec * kArcsecPerRad, 1.0, 4.5e-16);
  // A full turn: 360 deg = 2 pi rad, 1296000" = 2 pi rad.
  EXPECT_NEAR(360.0 * kRadPerDeg, 2.0 * M_PI, 1e-15);
  EXPECT_NEAR(1296000.0 * kRadPerArcsec, 2.0 * M_PI, 1e-14);
}

}  // namespace
}  // namespace imscal
