// The bias random walk: its prefix sums against the direct integral, and its estimate from the
// residuals of a fit of increments that carry a known walk.
#include "hrg_gyro/core/estimation/bias_random_walk.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace hrg_gyro {
namespace core {
namespace {

TEST(BiasRandomWalkTest, ScoreCovarianceIsTheIntegralOfTheLaterSums) {
  // integral over [0, t_last] of S(s) S(s)^T ds, S(s) the sum of w dt over the increments after s.
  BiasRandomWalk walk(1);
  const double t_mid[] = {1.0, 2.0, 4.0}, dt[] = {0.5, 1.0, 2.0};
  const Eigen::Vector2d w[] = {Eigen::Vector2d(1.0, -2.0), Eigen::Vector2d(0.5, 3.0), Eigen::Vector2d(-1.5, 0.25)};
  for (int i = 0; i < 3; ++i) walk.add(w[i], dt[i], t_mid[i]);
  Eigen::Matrix2d direct = Eigen::Matrix2d::Zero();
  double from = 0.0;
  for (int i = 0; i < 3; ++i) {  // on (from, t_mid[i]) the increments i.. are later
    Eigen::Vector2d s = Eigen::Vector2d::Zero();
    for (int j = i; j < 3; ++j) s += dt[j] * w[j];
    direct += (t_mid[i] - from) * s * s.transpose();
    from = t_mid[i];
  }
  EXPECT_LT((walk.scoreCovariance() - direct).cwiseAbs().maxCoeff(), 1e-12 * direct.cwiseAbs().maxCoeff());
  Eigen::Matrix2d arw = Eigen::Matrix2d::Zero();
  for (int i = 0; i < 3; ++i) arw += dt[i] * w[i] * w[i].transpose();
  EXPECT_LT((walk.angleWalkProducts() - arw).cwiseAbs().maxCoeff(), 1e-12);
}

TEST(BiasRandomWalkTest, RecoversAKnownRateRandomWalkFromTheResiduals) {
  // Increments of 1 s, y = K0 phi-step + D0 dt + the walk's dt b(t) + angle random walk; the fit of
  // K0 and D0 takes part of the walk, which the estimate accounts for.
  const double q = 2e-4, n_arw = 5e-4, k0 = -0.56, d0 = 1e-3;
  std::mt19937_64 random(17);
  std::normal_distribution<double> normal(0.0, 1.0);
  BiasRandomWalk walk(2);
  IncrementBlocks blocks(2);
  double bias = 0.0;
  for (int n = 1; n <= 6000; ++n) {
    WindowIncrement inc;
    inc.dt = 1.0;
    inc.t_mid = n - 0.5;
    inc.count_before = inc.count_after = 1000.0;
    inc.dw = Eigen::VectorXd(3);
    inc.dw(0) = (n / 500) % 2 ? 0.05 : -0.05;  // the table's step, plateaus of 500 s
    inc.dw(1) = inc.dt;
    inc.dw(2) = k0 * inc.dw(0) + (d0 + bias) * inc.dt + n_arw * std::sqrt(inc.dt) * normal(random);
    bias += q * normal(random);
    walk.add(inc.dw, inc.dt, inc.t_mid);
    blocks.add(inc, walk.prefix(), walk.prefixMoment());
  }
  const std::vector<IncrementBlock> all = blocks.blocks();
  const Eigen::MatrixXd total = IncrementBlocks::total(all);
  const std::vector<int> sel = {0, 1};
  const LeastSquaresSolution solution =
      solveNormalEquations(total.topLeftCorner(2, 2), total.block(0, 2, 2, 1).col(0), ColumnScaling::kUnitNorm, 1e8);
  ASSERT_TRUE(solution.ok);
  const BiasWalkFit fit = walk.estimate(all, sel, Eigen::MatrixXd::Identity(3, 3), solution);
  std::printf("q %.3g +- %.2g (true %.3g), N %.3g (true %.3g), %zu blocks\n", fit.rate_random_walk,
              fit.rate_random_walk_std, q, fit.angle_random_walk, n_arw, all.size());
  ASSERT_TRUE(fit.carried);
  EXPECT_NEAR(fit.rate_random_walk, q, 0.35 * q);
  EXPECT_LT(std::abs(fit.rate_random_walk - q), 3.0 * fit.rate_random_walk_std);
  // The covariance it predicts for the coefficients: a variance for each.
  const Eigen::MatrixXd covariance =
      walk.covariance(fit, sel, Eigen::MatrixXd::Identity(3, 3), solution.normal_inverse);
  EXPECT_GT(covariance(0, 0), 0.0);
  EXPECT_GT(covariance(1, 1), 0.0);
}

}  // namespace
}  // namespace core
}  // namespace hrg_gyro
