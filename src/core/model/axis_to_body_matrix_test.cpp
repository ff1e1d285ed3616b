// The axis-to-body matrix's readings: how far M or A is from the nominal axes, the angles and scales
// a triad file's reader sees, and M's standard errors from A's against the spread of M = A^-1 over
// many A drawn with those errors.
#include "hrg_gyro/core/model/axis_to_body_matrix.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <random>

namespace hrg_gyro {
namespace core {
namespace {

Eigen::Matrix3d misaligned() {
  Eigen::Matrix3d a;
  a << 1.0 + 2e-5, 1.2e-4, -8e-5, -6e-5, 1.0 - 1e-5, 2.1e-4, 1.5e-4, -9e-5, 1.0;
  return a;
}

TEST(AxisToBodyMatrixTest, TheLargestMisalignmentIsTheLargestEntryOffTheIdentity) {
  EXPECT_EQ(largestMisalignment(Eigen::Matrix3d::Identity()), 0.0);
  EXPECT_EQ(largestMisalignment(misaligned()), 2.1e-4);
  Eigen::Matrix3d swapped;
  swapped << 0, 1, 0, 1, 0, 0, 0, 0, 1;  // two axes exchanged: far beyond the bound
  EXPECT_GT(largestMisalignment(swapped), kMaxTriadMisalignment);
}

TEST(AxisToBodyMatrixTest, TheAnglesAndScalesAreReadFromA) {
  const std::string text = describeAlignment(misaligned());
  EXPECT_NE(text.find("xy 1.200e-04  xz -8.000e-05  yx -6.000e-05  yz 2.100e-04  zx 1.500e-04  zy -9.000e-05"),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("residual scale A_ii - 1: 2.000e-05  -1.000e-05  0.000e+00"), std::string::npos) << text;
}

TEST(AxisToBodyMatrixTest, MsStandardErrorsAreTheSpreadOfTheInverse) {
  const Eigen::Matrix3d a = misaligned();
  Eigen::Matrix3d a_std;
  a_std << 1e-6, 2e-6, 3e-6, 4e-6, 1e-6, 2e-6, 3e-6, 4e-6, 5e-6;
  const Eigen::Matrix3d m = a.inverse();
  const Eigen::Matrix3d predicted = axisToBodyStd(m, a_std);
  std::mt19937_64 random(7);
  std::normal_distribution<double> normal;
  Eigen::Matrix3d sum = Eigen::Matrix3d::Zero(), squares = Eigen::Matrix3d::Zero();
  const int n = 20000;
  for (int k = 0; k < n; ++k) {
    Eigen::Matrix3d drawn = a;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) drawn(i, j) += a_std(i, j) * normal(random);
    const Eigen::Matrix3d d = drawn.inverse() - m;
    sum += d;
    squares += d.cwiseAbs2();
  }
  const Eigen::Matrix3d spread = (squares / n - (sum / n).cwiseAbs2()).cwiseSqrt();
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) EXPECT_NEAR(spread(i, j) / predicted(i, j), 1.0, 0.03) << i << "," << j;
}

}  // namespace
}  // namespace core
}  // namespace hrg_gyro
