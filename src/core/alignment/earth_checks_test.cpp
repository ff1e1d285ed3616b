#include "hrg_gyro/core/alignment/earth_checks.h"

#include <gtest/gtest.h>

#include <cmath>

#include "hrg_gyro/core/alignment/local_level.h"
#include "hrg_gyro/core/common/units.h"

namespace hrg_gyro {
namespace core {
namespace {

constexpr double kLatitude = 0.9, kSigma = 1e-8;

// The Earth's rate and up seen by a body at `attitude`.
void seen(const EulerAngles& attitude, double latitude, Eigen::Vector3d* w, Eigen::Vector3d* up) {
  const Eigen::Matrix3d c = orientationFromEuler(attitude).toRotationMatrix();
  *w = c.transpose() * earthRateEnu(latitude);
  *up = c.transpose() * Eigen::Vector3d::UnitZ();
}

TEST(EarthChecksTest, WhatTheEarthDoesPasses) {
  Eigen::Vector3d w, up;
  seen(EulerAngles{0.02, -0.01, 1.3}, kLatitude, &w, &up);
  const auto checks = checkAgainstTheEarth(w, kSigma * kSigma * Eigen::Matrix3d::Identity(), up,
                                           1e-10 * Eigen::Matrix3d::Identity(), kLatitude, 5.0);
  ASSERT_EQ(checks.size(), 3u);
  EXPECT_FALSE(firstFailed(checks));
  EXPECT_NEAR(checks[0].measured, kEarthRotationRate, 1e-15);
  EXPECT_NEAR(checks[1].measured, kEarthRotationRate * std::sin(kLatitude), 1e-15);
  EXPECT_NEAR(checks[2].measured, 0.5 * kPi - kLatitude, 1e-9);
}

TEST(EarthChecksTest, GravityForTheSpecificForceAWrongLatitudeOrItsSignAreRefused) {
  Eigen::Vector3d w, up;
  seen(EulerAngles{0.02, -0.01, 1.3}, kLatitude, &w, &up);
  const Eigen::Matrix3d wc = kSigma * kSigma * Eigen::Matrix3d::Identity(), uc = 1e-10 * Eigen::Matrix3d::Identity();
  // An accelerometer that reports -g up: the angle to the rate is 90 deg + lat.
  const std::optional<EarthCheck> flipped = firstFailed(checkAgainstTheEarth(w, wc, -up, uc, kLatitude, 5.0));
  ASSERT_TRUE(flipped);
  EXPECT_EQ(flipped->name, "vertical");
  EXPECT_NE(flipped->describe().find("gravity (-g up)"), std::string::npos);
  // Latitude 0.95 declared at a 0.9 site: the vertical part is 2.3e-6 rad/s off, 230 sigmas.
  const std::optional<EarthCheck> wrong = firstFailed(checkAgainstTheEarth(w, wc, up, uc, 0.95, 5.0));
  ASSERT_TRUE(wrong);
  EXPECT_EQ(wrong->name, "vertical");
  EXPECT_GT(std::abs(wrong->measured - wrong->expected) / wrong->sigma, 100.0);
  // Its sign.
  ASSERT_TRUE(firstFailed(checkAgainstTheEarth(w, wc, up, uc, -kLatitude, 5.0)));
  // A gyro scale 1 % off: the length.
  const std::optional<EarthCheck> scaled = firstFailed(checkAgainstTheEarth(1.01 * w, wc, up, uc, kLatitude, 5.0));
  ASSERT_TRUE(scaled);
  EXPECT_EQ(scaled->name, "length");
}

TEST(EarthChecksTest, AnAccelerometerAxisReversedOnATiltedBodyIsRefused) {
  // The body pitched 0.05 rad with its x toward North: its accelerometer's x reversed tips the up by
  // 0.1 rad in the meridian, which turns the angle to the Earth's rate.
  Eigen::Vector3d w, up;
  seen(EulerAngles{0.0, 0.05, kPi / 2}, kLatitude, &w, &up);
  const Eigen::Vector3d reversed(-up.x(), up.y(), up.z());
  const std::optional<EarthCheck> failed = firstFailed(checkAgainstTheEarth(
      w, kSigma * kSigma * Eigen::Matrix3d::Identity(), reversed, 1e-10 * Eigen::Matrix3d::Identity(), kLatitude, 5.0));
  ASSERT_TRUE(failed);
}

TEST(EarthChecksTest, ATiltAboutNorthPassesUnseenAsDocumented) {
  // What no check sees: u tipped about North leaves w . u and the angle unchanged to first order.
  Eigen::Vector3d w, up;
  seen(EulerAngles{0.0, 0.0, kPi / 2}, kLatitude, &w, &up);  // body x North, y West
  const Eigen::Vector3d tipped = (Eigen::AngleAxisd(1e-3, Eigen::Vector3d::UnitX()) * up).normalized();
  EXPECT_FALSE(firstFailed(checkAgainstTheEarth(w, kSigma * kSigma * Eigen::Matrix3d::Identity(), tipped,
                                                1e-10 * Eigen::Matrix3d::Identity(), kLatitude, 5.0)));
}

TEST(EarthChecksTest, TheUpsCovarianceFollowsTheLevel) {
  const Eigen::Matrix2d level = Eigen::Vector2d(1e-6, 4e-6).asDiagonal();
  const Eigen::Matrix3d u = upCovarianceFromLevel(0.0, 0.0, level);
  // At level, roll moves up along y, pitch along -x.
  EXPECT_NEAR(u(0, 0), 4e-6, 1e-18);
  EXPECT_NEAR(u(1, 1), 1e-6, 1e-18);
  EXPECT_NEAR(u(2, 2), 0.0, 1e-18);
}

}  // namespace
}  // namespace core
}  // namespace hrg_gyro
