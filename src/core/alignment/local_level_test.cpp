// The frames and signs of north-finding: a body whose x points North has a true heading of 0 deg and
// a yaw of +90 deg; the specific force at rest gives back roll and pitch; the ENU small rotation and the
// (roll, pitch, yaw) changes map through E as finite differences say.
#include "hrg_gyro/core/alignment/local_level.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>

#include "hrg_gyro/core/common/units.h"

namespace hrg_gyro {
namespace core {
namespace {

TEST(LocalLevelTest, HeadingIsClockwiseFromNorthAndYawCounterClockwiseFromEast) {
  const Eigen::Vector3d north(0, 1, 0), east(1, 0, 0);
  // Body x along North: yaw +90 deg, true heading 0.
  EulerAngles a;
  a.yaw = kPi / 2;
  EXPECT_LT((orientationFromEuler(a) * Eigen::Vector3d::UnitX() - north).norm(), 1e-15);
  EXPECT_NEAR(trueHeadingDegrees(a.yaw), 0.0, 1e-12);
  // Body x along East: yaw 0, heading 90; along West: heading 270; along South: 180.
  EXPECT_NEAR(trueHeadingDegrees(0.0), 90.0, 1e-12);
  EXPECT_NEAR(trueHeadingDegrees(kPi), 270.0, 1e-12);
  EXPECT_NEAR(trueHeadingDegrees(-kPi / 2), 180.0, 1e-12);
  a.yaw = 0.0;
  EXPECT_LT((orientationFromEuler(a) * Eigen::Vector3d::UnitX() - east).norm(), 1e-15);
  for (double heading : {0.0, 12.5, 90.0, 181.0, 359.9}) {
    EXPECT_NEAR(trueHeadingDegrees(yawFromTrueHeading(heading)), heading, 1e-9) << heading;
  }
  // A heading just below North stays in [0, 360).
  const double h = trueHeadingDegrees(kPi / 2 + 1e-9);
  EXPECT_GE(h, 0.0);
  EXPECT_LT(h, 360.0);
}

TEST(LocalLevelTest, EarthRateInEnu) {
  const Eigen::Vector3d w = earthRateEnu(0.9);
  EXPECT_EQ(w.x(), 0.0);
  EXPECT_NEAR(w.y(), kEarthRotationRate * std::cos(0.9), 1e-20);
  EXPECT_NEAR(w.z(), kEarthRotationRate * std::sin(0.9), 1e-20);
  EXPECT_NEAR(horizontalEarthRate(0.9), 4.5328514e-5, 1e-12);  // 7.292115e-5 cos(0.9)
}

TEST(LocalLevelTest, EulerAnglesRoundTripAndLevelFromGravity) {
  for (const EulerAngles& a :
       {EulerAngles{0.01, -0.02, 0.3}, EulerAngles{-0.4, 0.3, -2.9}, EulerAngles{1.0, -1.2, 3.1}}) {
    const Eigen::Quaterniond q = orientationFromEuler(a);
    const EulerAngles b = eulerFromOrientation(q);
    EXPECT_NEAR(b.roll, a.roll, 1e-12);
    EXPECT_NEAR(b.pitch, a.pitch, 1e-12);
    EXPECT_NEAR(b.yaw, a.yaw, 1e-12);
    // f_b = C^T (0, 0, g) at rest.
    const Eigen::Vector3d f = q.toRotationMatrix().transpose() * Eigen::Vector3d(0, 0, kStandardGravity);
    const EulerAngles level = levelFromSpecificForce(f);
    EXPECT_NEAR(level.roll, a.roll, 1e-12);
    EXPECT_NEAR(level.pitch, a.pitch, 1e-12);
    // The level rotation takes the body's gravity to the vertical.
    EXPECT_LT((levelRotation(a.roll, a.pitch) * f - Eigen::Vector3d(0, 0, kStandardGravity)).norm(), 1e-12);
    // The level's Jacobian against central differences.
    const Eigen::Matrix<double, 2, 3> j = levelJacobian(f);
    for (int i = 0; i < 3; ++i) {
      const double d = 1e-6;
      Eigen::Vector3d fp = f, fm = f;
      fp(i) += d;
      fm(i) -= d;
      const EulerAngles p = levelFromSpecificForce(fp), m = levelFromSpecificForce(fm);
      EXPECT_NEAR(j(0, i), (p.roll - m.roll) / (2 * d), 1e-8);
      EXPECT_NEAR(j(1, i), (p.pitch - m.pitch) / (2 * d), 1e-8);
    }
    // The level rotation's derivatives.
    const double d = 1e-7;
    const Eigen::Matrix3d by_roll = (levelRotation(a.roll + d, a.pitch) - levelRotation(a.roll - d, a.pitch)) / (2 * d);
    const Eigen::Matrix3d by_pitch =
        (levelRotation(a.roll, a.pitch + d) - levelRotation(a.roll, a.pitch - d)) / (2 * d);
    EXPECT_LT((by_roll - levelRotationByRoll(a.roll, a.pitch)).norm(), 1e-8);
    EXPECT_LT((by_pitch - levelRotationByPitch(a.roll, a.pitch)).norm(), 1e-8);
  }
}

TEST(LocalLevelTest, SmallRotationsInEnuMapToEulerChangesThroughE) {
  const EulerAngles a{0.05, -0.1, 1.2};
  const Eigen::Matrix3d c = orientationFromEuler(a).toRotationMatrix();
  const Eigen::Matrix3d e = eulerToEnuRotation(a);
  for (int k = 0; k < 3; ++k) {
    const double d = 1e-7;
    EulerAngles p = a;
    (k == 0 ? p.roll : k == 1 ? p.pitch : p.yaw) += d;
    // (I + [delta x]) C = C(p): delta from the skew part of C(p) C^T - I.
    const Eigen::Matrix3d s = orientationFromEuler(p).toRotationMatrix() * c.transpose();
    const Eigen::Vector3d delta(0.5 * (s(2, 1) - s(1, 2)), 0.5 * (s(0, 2) - s(2, 0)), 0.5 * (s(1, 0) - s(0, 1)));
    EXPECT_LT((delta / d - e.col(k)).norm(), 1e-6) << k;
  }
  const Eigen::Matrix3d p = Eigen::Vector3d(1e-8, 4e-8, 9e-8).asDiagonal();
  const Eigen::Matrix3d back = enuCovarianceFromEuler(a, eulerCovarianceFromEnu(a, p));
  EXPECT_LT((back - p).norm(), 1e-20);
  // A level body: the ENU z error is the yaw error.
  const EulerAngles level{0.0, 0.0, 0.7};
  EXPECT_NEAR(eulerCovarianceFromEnu(level, p)(2, 2), 9e-8, 1e-20);
}

TEST(LocalLevelTest, RotationVectorToQuaternion) {
  const Eigen::Vector3d v(0.3, -0.2, 0.9);
  const Eigen::Quaterniond q = rotationVectorToQuaternion(v);
  const Eigen::AngleAxisd expected(v.norm(), v.normalized());
  EXPECT_LT((q.toRotationMatrix() - expected.toRotationMatrix()).norm(), 1e-14);
  EXPECT_NEAR(rotationVectorToQuaternion(Eigen::Vector3d(1e-12, 0, 0)).x(), 5e-13, 1e-25);
}

}  // namespace
}  // namespace core
}  // namespace hrg_gyro
