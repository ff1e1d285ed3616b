#include "hrg_gyro/core/common/weighted_least_squares.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

namespace hrg_gyro {
namespace core {

double conditionNumber(double largest, double smallest) { return smallest > 0.0 ? largest / smallest : INFINITY; }

LeastSquaresSolution solveWeightedDesign(const Eigen::MatrixXd& a, const Eigen::VectorXd& b, double max_condition) {
  LeastSquaresSolution s;
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(a);
  const Eigen::VectorXd sv = svd.singularValues();
  s.condition_number = conditionNumber(sv(0), sv(sv.size() - 1));
  if (!(s.condition_number <= max_condition)) return s;
  s.coefficients = a.colPivHouseholderQr().solve(b);
  s.residual_squares = (b - a * s.coefficients).squaredNorm();
  s.normal_inverse = (a.transpose() * a).inverse();
  s.ok = true;
  return s;
}

LeastSquaresSolution solveNormalEquations(const Eigen::MatrixXd& normal, const Eigen::VectorXd& rhs,
                                          ColumnScaling scaling, double max_condition) {
  LeastSquaresSolution s;
  const Eigen::Index p = normal.rows();
  Eigen::VectorXd scale = Eigen::VectorXd::Ones(p);
  if (scaling == ColumnScaling::kUnitNorm) {
    for (Eigen::Index c = 0; c < p; ++c) {
      if (!(normal(c, c) > 0.0)) {
        s.condition_number = INFINITY;
        return s;
      }
      scale[c] = 1.0 / std::sqrt(normal(c, c));
    }
  }
  const Eigen::MatrixXd scaled = scale.asDiagonal() * normal * scale.asDiagonal();
  // The normal matrix is symmetric positive (semi)definite: its singular values are its eigenvalues,
  // the squares of the design matrix's singular values.
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(scaled, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Eigen::VectorXd sv = svd.singularValues();
  s.condition_number = std::sqrt(conditionNumber(sv[0], sv[p - 1]));
  if (!(s.condition_number <= max_condition)) return s;
  const Eigen::MatrixXd scaled_inverse = svd.matrixV() * sv.cwiseInverse().asDiagonal() * svd.matrixU().transpose();
  s.normal_inverse = scale.asDiagonal() * scaled_inverse * scale.asDiagonal();
  s.coefficients = s.normal_inverse * rhs;
  s.ok = true;
  return s;
}

double residualSquaresFromNormal(double yty, const Eigen::MatrixXd& normal, const Eigen::VectorXd& rhs,
                                 const Eigen::VectorXd& c) {
  return std::max(0.0, yty - 2.0 * c.dot(rhs) + c.dot(normal * c));
}

double residualVariance(double residual_squares, std::size_t points, std::size_t parameters) {
  return residual_squares / static_cast<double>(points - parameters);
}

Eigen::MatrixXd residualCovariance(const Eigen::MatrixXd& normal_inverse, double residual_variance) {
  return residual_variance * normal_inverse;
}

Eigen::MatrixXd sandwichCovariance(const Eigen::MatrixXd& normal_inverse, const std::vector<CorrelatedBlock>& blocks,
                                   double residual_variance, std::size_t parameters) {
  std::size_t n = 0;
  double predicted = 0.0;  // mean of w V_ii: the residual variance per unit weight the model predicts
  for (const CorrelatedBlock& b : blocks) {
    const Eigen::VectorXd& w = *b.weights;
    for (Eigen::Index i = 0; i < w.size(); ++i) predicted += w[i] * (*b.covariance)(i, i);
    n += static_cast<std::size_t>(w.size());
  }
  predicted /= static_cast<double>(n);
  const double significant = predicted * (1.0 + 3.0 * std::sqrt(2.0 / static_cast<double>(n - parameters)));
  const double excess = std::max(0.0, residual_variance - significant);  // continuous: no jump at the threshold
  const Eigen::Index p = normal_inverse.rows();
  Eigen::MatrixXd meat = Eigen::MatrixXd::Zero(p, p);
  for (const CorrelatedBlock& b : blocks) {
    const Eigen::VectorXd& w = *b.weights;
    Eigen::MatrixXd v = *b.covariance;
    for (Eigen::Index i = 0; i < v.rows(); ++i) v(i, i) += excess / w[i];
    const Eigen::MatrixXd xw = b.design->transpose() * w.asDiagonal();
    meat.noalias() += xw * v * xw.transpose();
  }
  return normal_inverse * meat * normal_inverse;
}

}  // namespace core
}  // namespace hrg_gyro
