// The heading from an Earth's rate vector and a level: exact for the exact rate at any attitude; a bias
// across the horizontal Earth rate moves it by b / (Omega cos lat); a tilt about North (the East axis
// tipped) by tan(lat) times the tilt, one about East not at all; the budget says so.
#include "hrg_gyro/core/alignment/earth_rate_heading.h"

#include <gtest/gtest.h>

#include <cmath>

#include "hrg_gyro/core/common/units.h"
#include "hrg_gyro/core/model/earth_rate.h"

namespace hrg_gyro {
namespace core {
namespace {

EarthRateMeasurement exact(const EulerAngles& a, double latitude) {
  EarthRateMeasurement m;
  m.rate = orientationFromEuler(a).toRotationMatrix().transpose() * earthRateEnu(latitude);
  return m;
}

TEST(EarthRateHeadingTest, TheExactRateGivesTheExactAttitude) {
  for (const EulerAngles& a : {EulerAngles{0.0, 0.0, 0.3}, EulerAngles{0.02, -0.03, -2.0}, EulerAngles{-0.3, 0.4, 3.1},
                               EulerAngles{0.0, 0.0, -kPi + 1e-6}}) {
    for (double latitude : {-0.7, 0.0, 0.9, 1.3}) {
      LevelMeasurement level;
      level.roll = a.roll;
      level.pitch = a.pitch;
      const HeadingSolution h = solveHeading(exact(a, latitude), level, latitude);
      EXPECT_NEAR(wrapToPi(h.attitude.yaw - a.yaw), 0.0, 1e-12) << latitude;
      EXPECT_NEAR(h.horizontal_rate, horizontalEarthRate(latitude), 1e-18);
      EXPECT_NEAR(h.levelled_rate.z(), verticalEarthRate(latitude), 1e-18);
      EXPECT_LT(h.orientation.angularDistance(orientationFromEuler(a)), 1e-12);
    }
  }
}

TEST(EarthRateHeadingTest, ErrorsEnterAsTheBudgetSays) {
  const double latitude = 0.9, h = horizontalEarthRate(latitude);
  const EulerAngles a{0.0, 0.0, 0.4};
  LevelMeasurement level;
  // A bias of 1e-8 rad/s across the Earth's horizontal rate: 1e-8 / h of yaw.
  EarthRateMeasurement m = exact(a, latitude);
  const Eigen::Vector3d across(std::cos(a.yaw), -std::sin(a.yaw), 0.0);  // body frame = levelled frame here
  m.rate += 1e-8 * across;
  const double moved = wrapToPi(solveHeading(m, level, latitude).attitude.yaw - a.yaw);
  EXPECT_NEAR(moved, 1e-8 / h, 1e-4 * 1e-8 / h);
  // Its variance in the budget: 1e-8 rad/s on each horizontal axis gives 1e-8 / h of yaw.
  m.residual_bias = Eigen::Vector3d(1e-16, 1e-16, 1e-16).asDiagonal();
  EXPECT_NEAR(solveHeading(m, level, latitude).budget.residual_bias, 1e-8 / h, 1e-12);
  // A tilt about the North axis, by declaring the level 1 mrad off: it tips the vertical Earth rate
  // into the East component, tan(lat) mrad of yaw. The body's x points along yaw 0.4 from East, so
  // North is roll and pitch mixed: rotate the 1 mrad into them.
  const double tilt = 1e-3;
  const Eigen::Vector2d north_in_body(std::sin(a.yaw), std::cos(a.yaw));  // North in the levelled body axes
  level.roll = tilt * north_in_body.x();
  level.pitch = tilt * north_in_body.y();
  const HeadingSolution tilted = solveHeading(exact(a, latitude), level, latitude);
  const double shift = std::abs(wrapToPi(tilted.attitude.yaw - a.yaw));
  EXPECT_NEAR(shift, std::tan(latitude) * tilt, 0.01 * std::tan(latitude) * tilt);
  // About East: it tips the vertical rate along the horizontal one, nothing to first order.
  level.roll = tilt * std::cos(a.yaw);
  level.pitch = -tilt * std::sin(a.yaw);
  EXPECT_LT(std::abs(wrapToPi(solveHeading(exact(a, latitude), level, latitude).attitude.yaw - a.yaw)), 1e-3 * tilt);
  // A level sigma of 1 mrad on roll and pitch: tan(lat) mrad of yaw in the budget.
  level.roll = level.pitch = 0.0;
  level.covariance = Eigen::Vector2d(1e-6, 1e-6).asDiagonal();
  const HeadingSolution budgeted = solveHeading(exact(a, latitude), level, latitude);
  EXPECT_NEAR(budgeted.budget.level, std::tan(latitude) * 1e-3, 1e-3 * std::tan(latitude) * 1e-3);
  EXPECT_NEAR(budgeted.budget.total, budgeted.budget.level, 1e-12);
  std::printf(
      "[ measured ] lat 0.9 rad: 1e-8 rad/s across -> %.4f mrad (1/h = %.4f); 1 mrad tilt about North -> %.4f mrad "
      "(tan lat %.4f)\n",
      1e3 * moved, 1e3 * 1e-8 / h, 1e3 * shift, std::tan(latitude));
}

}  // namespace
}  // namespace core
}  // namespace hrg_gyro
