#include "hrg_gyro/core/alignment/body_attitude_track.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>

#include "hrg_gyro/core/alignment/local_level.h"

namespace hrg_gyro {
namespace core {
namespace {

constexpr double kDt = 0.005;

Eigen::Vector3d rotationVector(const Eigen::Matrix3d& r) {
  const Eigen::AngleAxisd a(r);
  return a.axis() * a.angle();
}

TEST(BodyAttitudeTrackTest, AConstantRateIsTheExactRotation) {
  BodyAttitudeTrack track(10.0);
  const Eigen::Vector3d w(1e-3, -2e-3, 5e-4);
  for (int k = 1; k <= 2000; ++k) ASSERT_TRUE(track.add(10.0 + k * kDt, kDt, w * kDt));
  EXPECT_EQ(track.size(), 2000u);
  EXPECT_LT((rotationVector(track.attitudeAt(20.0)) - w * 10.0).norm(), 1e-13);
  EXPECT_LT((rotationVector(track.attitudeAt(15.0025)) - w * 5.0025).norm(), 1e-13);  // within a sample
  EXPECT_LT((track.meanRate() - w).norm(), 1e-15);
  // S(T) = int_0^T Exp([w x] s) ds = T I + (1 - cos a) / |w|^2 [w x] + (T - sin a / |w|) / |w|^2 [w x]^2,
  // a = |w| T: exact for a constant rate.
  Eigen::Matrix3d wx;
  wx << 0.0, -w.z(), w.y(), w.z(), 0.0, -w.x(), -w.y(), w.x(), 0.0;
  const double t = 10.0, n = w.norm(), a = n * t;
  const Eigen::Matrix3d exact =
      t * Eigen::Matrix3d::Identity() + (1.0 - std::cos(a)) / (n * n) * wx + (t - std::sin(a) / n) / (n * n) * wx * wx;
  EXPECT_LT((track.biasResponseAt(20.0) - exact).norm(), 1e-9);
}

TEST(BodyAttitudeTrackTest, TheConingCorrectionFollowsAnOscillationOfTwoAxes) {
  // A body coning: C(t) = Rz(a sin wt) Ry(a cos wt), whose rate has a rectified part the plain sum of
  // increments misses; the corrected track stays within the second order's remainder of the truth.
  const double a = 1e-3, w = 2.0 * 3.14159265358979 * 5.0;
  auto truth = [&](double t) {
    return Eigen::Matrix3d(Eigen::AngleAxisd(a * std::sin(w * t), Eigen::Vector3d::UnitZ()) *
                           Eigen::AngleAxisd(a * std::cos(w * t) - a, Eigen::Vector3d::UnitY()));
  };
  BodyAttitudeTrack corrected(0.0), plain(0.0);
  Eigen::Vector3d summed = Eigen::Vector3d::Zero();
  const int fine = 200;
  for (int k = 1; k <= 2000; ++k) {
    // The increment: the integral of the body rate over the sample, from the truth's fine steps.
    Eigen::Vector3d increment = Eigen::Vector3d::Zero();
    for (int j = 0; j < fine; ++j) {
      const double t0 = (k - 1 + double(j) / fine) * kDt, t1 = t0 + kDt / fine;
      increment += rotationVector(truth(t0).transpose() * truth(t1));
    }
    corrected.add(k * kDt, kDt, increment);
    summed += increment;
  }
  const Eigen::Matrix3d end = truth(10.0);
  const double with = rotationVector(end.transpose() * corrected.attitudeAt(10.0)).norm();
  const double without = (rotationVector(end) - summed).norm();
  EXPECT_LT(with, 0.05 * without) << "coning corrected " << with << " rad, summed " << without << " rad";
}

TEST(BodyAttitudeTrackTest, ASampleThatDoesNotContinueIsNotAdded) {
  BodyAttitudeTrack track(0.0);
  EXPECT_TRUE(track.add(kDt, kDt, Eigen::Vector3d::Zero()));
  EXPECT_FALSE(track.add(3.0 * kDt, kDt, Eigen::Vector3d::Zero()));  // one lost between
  EXPECT_FALSE(track.add(2.0 * kDt, 0.0, Eigen::Vector3d::Zero()));
  EXPECT_FALSE(track.add(2.0 * kDt, kDt, Eigen::Vector3d(NAN, 0.0, 0.0)));
  EXPECT_TRUE(track.add(2.0 * kDt + 1e-5, kDt, Eigen::Vector3d::Zero()));  // jitter within a tenth of dt
  EXPECT_EQ(track.size(), 2u);
}

}  // namespace
}  // namespace core
}  // namespace hrg_gyro
