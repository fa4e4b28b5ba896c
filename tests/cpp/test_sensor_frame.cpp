// lugrip::contact_wrench against a hand-computed point contact (independent reference: the
// moment a sensor measures is r x F plus the contact's torsion).
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <limits>

#include "lugrip/sensor_frame.hpp"

namespace {

using V3 = std::array<double, 3>;

V3 cross(const V3& a, const V3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}

TEST(SensorFrame, OffsetMovesTheTorsionToTheCentreOfPressure) {
  const double d = 0.012, x = 0.003, y = -0.002, tz = 2.5e-3;
  const V3 F{0.4, -0.7, 6.0};
  V3 M = cross({x, y, -d}, F);
  M[2] += tz;
  const auto row = lugrip::contact_wrench(F, M, {false, d}, 0.01);
  EXPECT_DOUBLE_EQ(row[0], F[2]);
  EXPECT_DOUBLE_EQ(row[1], F[0]);
  EXPECT_DOUBLE_EQ(row[2], F[1]);
  EXPECT_NEAR(row[3], tz, 1e-15);
  // a sensor mounted the other way round (z toward the object) reads the rotated wrench
  const V3 Fr{F[0], -F[1], -F[2]}, Mr{M[0], -M[1], -M[2]};
  const auto flipped = lugrip::contact_wrench(Fr, Mr, {true, d}, 0.01);
  for (int j = 0; j < 4; ++j) EXPECT_NEAR(flipped[j], row[j], 1e-15) << j;
  // without an offset the moment's z is taken as it is
  EXPECT_DOUBLE_EQ(lugrip::contact_wrench(F, M, {}, 0.01)[3], M[2]);
}

TEST(SensorFrame, BelowTheFloorOrNonFiniteTheMomentIsKept) {
  const V3 F{0.4, -0.7, 0.005}, M{1e-4, -2e-4, 3e-4};
  EXPECT_DOUBLE_EQ(lugrip::contact_wrench(F, M, {false, 0.01}, 0.01)[3], M[2]);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const auto row = lugrip::contact_wrench({0.1, 0.2, nan}, M, {false, 0.01}, 0.01);
  EXPECT_TRUE(std::isnan(row[0]));
  EXPECT_DOUBLE_EQ(row[3], M[2]);
  EXPECT_TRUE(std::isnan(lugrip::contact_wrench({nan, 0.2, 5.0}, M, {false, 0.01}, 0.01)[3]));
}

}  // namespace
