#include "hrg_gyro/core/model/earth_rate.h"

#include <gtest/gtest.h>

#include <cmath>

#include "hrg_gyro/core/common/units.h"

namespace hrg_gyro {
namespace core {
namespace {

TEST(EarthRate, PartsAtALatitude) {
  EXPECT_NEAR(horizontalEarthRate(0.9), 4.5328514e-5, 1e-12);  // 7.292115e-5 cos(0.9)
  EXPECT_NEAR(verticalEarthRate(0.9), 5.7121099e-5, 1e-12);    // 7.292115e-5 sin(0.9)
  EXPECT_EQ(verticalEarthRate(0.0), 0.0);
  EXPECT_NEAR(verticalEarthRate(0.5 * kPi), kEarthRotationRate, 1e-20);
  EXPECT_NEAR(horizontalEarthRate(-0.5 * kPi), 0.0, 1e-20);
  EXPECT_LT(verticalEarthRate(-0.3), 0.0);  // south of the equator the vertical part points down
}

TEST(EarthRate, EnuVectorIsItsParts) {
  for (const double lat : {-1.2, -0.4, 0.0, 0.7, 1.5}) {
    const Eigen::Vector3d w = earthRateEnu(lat);
    EXPECT_EQ(w.x(), 0.0);
    EXPECT_EQ(w.y(), horizontalEarthRate(lat));
    EXPECT_EQ(w.z(), verticalEarthRate(lat));
    EXPECT_NEAR(w.norm(), kEarthRotationRate, 1e-19);
  }
}

TEST(EarthRate, LatitudeRule) {
  EXPECT_TRUE(validLatitude(0.0));
  EXPECT_TRUE(validLatitude(0.5 * kPi));
  EXPECT_TRUE(validLatitude(-0.5 * kPi));
  EXPECT_FALSE(validLatitude(1.6));
  EXPECT_FALSE(validLatitude(-2.0));
  EXPECT_FALSE(validLatitude(NAN));
  EXPECT_FALSE(validLatitude(INFINITY));
}

}  // namespace
}  // namespace core
}  // namespace hrg_gyro
