// Weighted linear least squares: the one solver behind the fits of the core (the harmonic fit of
// binned or sampled points, the frequency-dependent thermal fit, the correction matrix).
//
// Two ways in, because the fits hold their data differently:
//  - the weighted design matrix A = W^1/2 X and b = W^1/2 y, for a fit whose points are all in
//    memory: solved by column-pivoting QR, which stays accurate up to condition numbers whose square
//    would ruin the normal equations;
//  - the normal equations N = X^T W X, r = X^T W y, for a fit streamed or assembled by blocks:
//    solved through the singular value decomposition of N, optionally with its columns scaled to
//    unit norm first (when the columns carry different units, e.g. K columns scaled by a table rate
//    beside D columns, the condition number should not count the units).
// Either way the fit is refused before it is solved when the condition number of the (weighted)
// design matrix exceeds the caller's limit, and (X^T W X)^-1 comes back for the covariances.
//
// Covariances: sigma^2 (X^T W X)^-1 for independent points; for points whose noise is correlated
// within blocks (telescoped bin rates), the sandwich (X^T W X)^-1 [sum_b X_b^T W_b V_b W_b X_b]
// (X^T W X)^-1 with each block's predicted covariance V_b. Scatter beyond what V predicts is added
// as independent noise of variance lambda / w, but only the part above the chance level of the
// scatter itself (3 sigma of its chi-square fluctuation): the errors never understate the data, and
// chance does not inflate the errors of coefficients the correlated noise barely reaches.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <vector>

namespace hrg_gyro {
namespace core {

/// Condition number of a matrix from its largest and smallest singular values; infinite when the
/// smallest is not positive.
double conditionNumber(double largest, double smallest);

struct LeastSquaresSolution {
  bool ok = false;                ///< false: condition number above the limit, nothing solved
  double condition_number = 0.0;  ///< of the weighted design matrix (unit-norm columns if asked)
  Eigen::VectorXd coefficients;
  Eigen::MatrixXd normal_inverse;  ///< (X^T W X)^-1, the covariance per unit residual variance
  /// Weighted residual sum of squares, sum w (y - X c)^2 (design form only).
  double residual_squares = 0.0;
};

/// Design form: weighted_design = W^1/2 X (n x p), weighted_values = W^1/2 y.
LeastSquaresSolution solveWeightedDesign(const Eigen::MatrixXd& weighted_design, const Eigen::VectorXd& weighted_values,
                                         double max_condition);

enum class ColumnScaling {
  kNone,      ///< condition number of N itself (columns in comparable units)
  kUnitNorm,  ///< condition number and solve with the design's columns scaled to unit weighted norm
};

/// Normal form: normal = X^T W X (p x p, symmetric), rhs = X^T W y. With kUnitNorm every diagonal
/// element must be positive (a column no data reach is reported as an infinite condition number).
LeastSquaresSolution solveNormalEquations(const Eigen::MatrixXd& normal, const Eigen::VectorXd& rhs,
                                          ColumnScaling scaling, double max_condition);

/// sum w (y - X c)^2 from the normal equations and y^T W y (for streamed fits that kept no points;
/// held at >= 0 against cancellation).
double residualSquaresFromNormal(double weighted_value_squares, const Eigen::MatrixXd& normal,
                                 const Eigen::VectorXd& rhs, const Eigen::VectorXd& coefficients);

/// Residual variance per unit weight, sigma^2 = residual_squares / (points - parameters).
double residualVariance(double residual_squares, std::size_t points, std::size_t parameters);

/// Independent points: sigma^2 (X^T W X)^-1.
Eigen::MatrixXd residualCovariance(const Eigen::MatrixXd& normal_inverse, double residual_variance);

/// Points whose noise is correlated among themselves only: their design rows X_b (unweighted),
/// weights w_b and predicted value covariance V_b.
struct CorrelatedBlock {
  const Eigen::MatrixXd* design;
  const Eigen::VectorXd* weights;
  const Eigen::MatrixXd* covariance;
};

/// The sandwich covariance over the blocks (all points of the fit), with the significant excess of
/// residual_variance over the predicted noise added as independent noise; `parameters` is p.
Eigen::MatrixXd sandwichCovariance(const Eigen::MatrixXd& normal_inverse, const std::vector<CorrelatedBlock>& blocks,
                                   double residual_variance, std::size_t parameters);

}  // namespace core
}  // namespace hrg_gyro
