// The per-bin sums of two groups give the known K(theta) and D(theta) at the bin centres.
#include "hrg_gyro/core/estimation/increment_bins.h"

#include <gtest/gtest.h>

#include <cmath>

#include "hrg_gyro/core/common/units.h"
#include "hrg_gyro/core/model/harmonic_model.h"

namespace hrg_gyro {
namespace core {
namespace {

const HarmonicModel kK({2}, -0.56, {0.01}, {-0.004});
const HarmonicModel kD({2}, 1e-5, {0.0}, {2e-5});
constexpr double kEarth = 5e-5;

/// An increment of `group` at wave angle theta over dt s at table rate w: y only (no columns).
WindowIncrement at(int group, double theta, double w, double dt) {
  WindowIncrement inc;
  inc.group = group;
  inc.theta_mid = theta;
  inc.dt = dt;
  inc.dphi = w * dt;
  inc.dw = Eigen::VectorXd::Constant(1, (kK(theta) * (w + kEarth) + kD(theta)) * dt);
  return inc;
}

TEST(IncrementBinsTest, TwoGroupsGiveTheKnownCurveAtTheBinCentres) {
  const int bins = 8;
  IncrementBins sums(bins, 0);
  for (int b = 0; b < bins; ++b) {
    const double centre = (b + 0.5) * kPi / bins;
    for (int i = 0; i < 4; ++i) {
      sums.add(at(0, centre, 0.05, 0.5));
      sums.add(at(1, centre + kPi, -0.05, 0.5));  // a turn later: the same bin
    }
    sums.add(at(2, centre, 0.2, 0.1));  // a third, smaller group: not used
  }
  sums.add(at(1, 0.5 * kPi / bins, -0.05, -1.9));  // bin 0 left with 0.1 s in group 1
  const HarmonicModel none({2}, 0.0, {0.0}, {0.0});
  // Nothing fitted (no columns): the curve is all residual; a model passed is added to it (the
  // fit's residual about its columns does not depend on the curve it is shown about).
  const IncrementBinnedCurves raw =
      sums.curves({}, Eigen::VectorXd(), Eigen::MatrixXd::Identity(1, 1), none, none, kEarth, 0.5);
  const IncrementBinnedCurves shown =
      sums.curves({}, Eigen::VectorXd(), Eigen::MatrixXd::Identity(1, 1), kK, kD, kEarth, 0.5);
  ASSERT_EQ(raw.points.size(), static_cast<std::size_t>(bins - 1));  // bin 0 below min_bin_time
  for (const BinnedCurvePoint& p : raw.points) {
    EXPECT_NEAR(p.k, kK(p.theta), 1e-12) << p.theta;
    EXPECT_NEAR(p.d, kD(p.theta), 1e-15) << p.theta;
    EXPECT_DOUBLE_EQ(p.weight, 2.0);
  }
  EXPECT_NEAR(raw.k_residual_rms, 0.56, 0.02);
  ASSERT_EQ(shown.points.size(), raw.points.size());
  for (std::size_t i = 0; i < raw.points.size(); ++i) {
    EXPECT_NEAR(shown.points[i].k, 2.0 * raw.points[i].k, 1e-12);
    EXPECT_NEAR(shown.points[i].d, 2.0 * raw.points[i].d, 1e-15);
  }
  EXPECT_EQ(shown.k_residual_rms, raw.k_residual_rms);
  EXPECT_EQ(shown.d_residual_rms, raw.d_residual_rms);
}

TEST(IncrementBinsTest, FoldsTheWaveAngleIntoHalfATurn) {
  const IncrementBins sums(8, 0);
  EXPECT_EQ(sums.binOf(0.01), 0);
  EXPECT_EQ(sums.binOf(-0.01), 7);
  EXPECT_EQ(sums.binOf(kPi + 0.01), 0);
  EXPECT_EQ(sums.binOf(3.0 * kPi - 0.01), 7);
  EXPECT_THROW(IncrementBins(0, 0), std::invalid_argument);
}

}  // namespace
}  // namespace core
}  // namespace hrg_gyro
