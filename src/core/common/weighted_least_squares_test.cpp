// The weighted least-squares solver: a line through three weighted points worked out by hand, a
// larger problem against Eigen's direct solve of the normal equations, refusals, and the sandwich
// covariance in the two cases it can be written down in closed form.
#include "hrg_gyro/core/common/weighted_least_squares.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>

namespace hrg_gyro {
namespace core {
namespace {

// y = c0 + c1 x through (0, 1), (1, 2), (2, 4) with weights 1, 1, 2. By hand:
//   N = X^T W X = [4 5; 5 9], det 11, X^T W y = (11, 18), c = (9/11, 17/11),
//   residuals (2/11, -4/11, 1/11), sum w r^2 = 22/121 = 2/11, sigma^2 = (2/11) / (3 - 2),
//   N^-1 = [9 -5; -5 4] / 11, y^T W y = 37.
struct LineProblem {
  Eigen::MatrixXd x{3, 2};
  Eigen::VectorXd y{3}, w{3};
  LineProblem() {
    x << 1, 0, 1, 1, 1, 2;
    y << 1, 2, 4;
    w << 1, 1, 2;
  }
  Eigen::MatrixXd normal() const { return x.transpose() * w.asDiagonal() * x; }
  Eigen::VectorXd rhs() const { return x.transpose() * w.asDiagonal() * y; }
  Eigen::MatrixXd weightedDesign() const { return w.cwiseSqrt().asDiagonal() * x; }
  Eigen::VectorXd weightedValues() const { return w.cwiseSqrt().asDiagonal() * y; }
};

Eigen::Matrix2d handNormalInverse() {
  Eigen::Matrix2d m;
  m << 9.0 / 11, -5.0 / 11, -5.0 / 11, 4.0 / 11;
  return m;
}

void expectHandSolution(const LeastSquaresSolution& s) {
  ASSERT_TRUE(s.ok);
  EXPECT_NEAR(s.coefficients[0], 9.0 / 11, 1e-14);
  EXPECT_NEAR(s.coefficients[1], 17.0 / 11, 1e-14);
  EXPECT_LT((s.normal_inverse - handNormalInverse()).cwiseAbs().maxCoeff(), 1e-14);
}

TEST(WeightedLeastSquaresTest, ConditionNumberOfSingularValues) {
  EXPECT_EQ(conditionNumber(4.0, 2.0), 2.0);
  EXPECT_EQ(conditionNumber(1.0, 0.0), INFINITY);
  EXPECT_EQ(conditionNumber(1.0, -1e-300), INFINITY);
}

TEST(WeightedLeastSquaresTest, DesignFormSolvesTheHandProblem) {
  const LineProblem lp;
  const LeastSquaresSolution s = solveWeightedDesign(lp.weightedDesign(), lp.weightedValues(), INFINITY);
  expectHandSolution(s);
  EXPECT_NEAR(s.residual_squares, 2.0 / 11, 1e-14);
  const Eigen::VectorXd sv = Eigen::JacobiSVD<Eigen::MatrixXd>(lp.weightedDesign()).singularValues();
  EXPECT_NEAR(s.condition_number, sv[0] / sv[1], 1e-12);
}

TEST(WeightedLeastSquaresTest, NormalFormSolvesTheHandProblem) {
  const LineProblem lp;
  const LeastSquaresSolution plain = solveNormalEquations(lp.normal(), lp.rhs(), ColumnScaling::kNone, INFINITY);
  expectHandSolution(plain);
  // Without scaling, the condition number is the design matrix's: sqrt of the normal matrix's.
  const Eigen::VectorXd sv = Eigen::JacobiSVD<Eigen::MatrixXd>(lp.weightedDesign()).singularValues();
  EXPECT_NEAR(plain.condition_number, sv[0] / sv[1], 1e-12);
  EXPECT_NEAR(residualSquaresFromNormal(37.0, lp.normal(), lp.rhs(), plain.coefficients), 2.0 / 11, 1e-13);

  // Scaling the columns changes the condition number (to the unit-norm design's), not the fit.
  const LeastSquaresSolution scaled = solveNormalEquations(lp.normal(), lp.rhs(), ColumnScaling::kUnitNorm, INFINITY);
  expectHandSolution(scaled);
  Eigen::MatrixXd unit = lp.weightedDesign();
  for (Eigen::Index c = 0; c < unit.cols(); ++c) unit.col(c) /= unit.col(c).norm();
  const Eigen::VectorXd usv = Eigen::JacobiSVD<Eigen::MatrixXd>(unit).singularValues();
  EXPECT_NEAR(scaled.condition_number, usv[0] / usv[1], 1e-12);
  EXPECT_GT(std::abs(scaled.condition_number - plain.condition_number), 0.1);
}

TEST(WeightedLeastSquaresTest, PlainCovarianceOfTheHandProblem) {
  const LineProblem lp;
  const LeastSquaresSolution s = solveWeightedDesign(lp.weightedDesign(), lp.weightedValues(), INFINITY);
  const double sigma2 = residualVariance(s.residual_squares, 3, 2);
  EXPECT_NEAR(sigma2, 2.0 / 11, 1e-14);
  const Eigen::MatrixXd cov = residualCovariance(s.normal_inverse, sigma2);
  EXPECT_LT((cov - (2.0 / 11) * handNormalInverse()).cwiseAbs().maxCoeff(), 1e-14);
}

TEST(WeightedLeastSquaresTest, AgreesWithEigensDirectSolve) {
  // 40 points, 5 columns of different scales, uneven weights, fixed pseudo-random values.
  const int n = 40, p = 5;
  Eigen::MatrixXd x(n, p);
  Eigen::VectorXd y(n), w(n);
  for (int i = 0; i < n; ++i) {
    const double t = 0.1 * i;
    x.row(i) << 1.0, t, std::cos(t), 100.0 * std::sin(2 * t), 1e-3 * t * t;
    y[i] = 0.3 - 0.2 * t + std::sin(7.0 * i);
    w[i] = 0.5 + std::fmod(0.37 * i, 1.0);
  }
  const Eigen::MatrixXd normal = x.transpose() * w.asDiagonal() * x;
  const Eigen::VectorXd rhs = x.transpose() * w.asDiagonal() * y;
  const Eigen::VectorXd direct = normal.ldlt().solve(rhs);
  const Eigen::MatrixXd direct_inverse = normal.inverse();
  auto close = [](const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
    return (a - b).cwiseAbs().maxCoeff() / b.cwiseAbs().maxCoeff();
  };

  const LeastSquaresSolution design =
      solveWeightedDesign(w.cwiseSqrt().asDiagonal() * x, w.cwiseSqrt().asDiagonal() * y, INFINITY);
  ASSERT_TRUE(design.ok);
  EXPECT_LT(close(design.coefficients, direct), 1e-9);
  EXPECT_LT(close(design.normal_inverse, direct_inverse), 1e-9);
  const double direct_ss = (w.array() * (y - x * direct).array().square()).sum();
  EXPECT_NEAR(design.residual_squares, direct_ss, 1e-9 * direct_ss);

  for (ColumnScaling scaling : {ColumnScaling::kNone, ColumnScaling::kUnitNorm}) {
    const LeastSquaresSolution s = solveNormalEquations(normal, rhs, scaling, INFINITY);
    ASSERT_TRUE(s.ok);
    EXPECT_LT(close(s.coefficients, direct), 1e-8);
    EXPECT_LT(close(s.normal_inverse, direct_inverse), 1e-8);
  }
}

TEST(WeightedLeastSquaresTest, RefusesIllConditionedFits) {
  const LineProblem lp;
  const LeastSquaresSolution design = solveWeightedDesign(lp.weightedDesign(), lp.weightedValues(), 1.5);
  EXPECT_FALSE(design.ok);
  EXPECT_GT(design.condition_number, 1.5);
  EXPECT_EQ(design.coefficients.size(), 0);

  // Two equal columns: singular.
  Eigen::MatrixXd x(3, 2);
  x << 1, 1, 2, 2, 3, 3;
  const Eigen::VectorXd y = Eigen::Vector3d(1, 2, 3);
  EXPECT_FALSE(solveWeightedDesign(x, y, 1e6).ok);
  const Eigen::MatrixXd normal = x.transpose() * x;
  EXPECT_FALSE(solveNormalEquations(normal, x.transpose() * y, ColumnScaling::kNone, 1e6).ok);
  EXPECT_FALSE(solveNormalEquations(normal, x.transpose() * y, ColumnScaling::kUnitNorm, 1e6).ok);

  // A column no data reach cannot be scaled to unit norm.
  Eigen::MatrixXd empty_column = Eigen::MatrixXd::Identity(2, 2);
  empty_column(1, 1) = 0.0;
  const LeastSquaresSolution unscalable =
      solveNormalEquations(empty_column, Eigen::Vector2d(1, 0), ColumnScaling::kUnitNorm, INFINITY);
  EXPECT_FALSE(unscalable.ok);
  EXPECT_EQ(unscalable.condition_number, INFINITY);
}

TEST(WeightedLeastSquaresTest, SandwichWithPredictedIndependentNoiseIsThePlainCovariance) {
  // V = s2 W^-1: the meat X^T W V W X is s2 N, so the sandwich is s2 N^-1 whenever the scatter is
  // below the significance level (residual variance <= s2 (1 + 3 sqrt(2 / dof))).
  const LineProblem lp;
  const LeastSquaresSolution s = solveWeightedDesign(lp.weightedDesign(), lp.weightedValues(), INFINITY);
  const double s2 = 0.05;
  const Eigen::MatrixXd v = s2 * lp.w.cwiseInverse().asDiagonal().toDenseMatrix();
  const Eigen::MatrixXd cov = sandwichCovariance(s.normal_inverse, {{&lp.x, &lp.w, &v}}, s2, 2);
  EXPECT_LT((cov - s2 * handNormalInverse()).cwiseAbs().maxCoeff(), 1e-15);

  // The same points as two independent blocks give the same sandwich.
  const Eigen::MatrixXd x1 = lp.x.topRows(1), x2 = lp.x.bottomRows(2);
  const Eigen::VectorXd w1 = lp.w.head(1), w2 = lp.w.tail(2);
  const Eigen::MatrixXd v1 = v.topLeftCorner(1, 1), v2 = v.bottomRightCorner(2, 2);
  const Eigen::MatrixXd split = sandwichCovariance(s.normal_inverse, {{&x1, &w1, &v1}, {&x2, &w2, &v2}}, s2, 2);
  EXPECT_LT((split - cov).cwiseAbs().maxCoeff(), 1e-15);
}

TEST(WeightedLeastSquaresTest, SandwichAddsOnlyTheSignificantExcessScatter) {
  // Residual variance r above the predicted s2: the excess over s2 (1 + 3 sqrt(2 / dof)) is added
  // as independent noise lambda / w, so the sandwich becomes (s2 + lambda) N^-1.
  const LineProblem lp;
  const LeastSquaresSolution s = solveWeightedDesign(lp.weightedDesign(), lp.weightedValues(), INFINITY);
  const double s2 = 0.01, r = 0.2;
  const double lambda = r - s2 * (1.0 + 3.0 * std::sqrt(2.0 / 1.0));
  ASSERT_GT(lambda, 0.0);
  const Eigen::MatrixXd v = s2 * lp.w.cwiseInverse().asDiagonal().toDenseMatrix();
  const Eigen::MatrixXd cov = sandwichCovariance(s.normal_inverse, {{&lp.x, &lp.w, &v}}, r, 2);
  EXPECT_LT((cov - (s2 + lambda) * handNormalInverse()).cwiseAbs().maxCoeff(), 1e-15);
}

}  // namespace
}  // namespace core
}  // namespace hrg_gyro
