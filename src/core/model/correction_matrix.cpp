#include "hrg_gyro/core/model/correction_matrix.h"

#include <algorithm>
#include <cmath>

#include "hrg_gyro/core/common/weighted_least_squares.h"

namespace hrg_gyro {
namespace core {

Eigen::Matrix4d CorrectionMatrix::matrix() const {
  Eigen::Matrix4d m = Eigen::Matrix4d::Zero();
  m(kAc, kAc) = p[0];
  m(kAc, kAs) = p[2];
  m(kBc, kBc) = p[0];
  m(kBc, kBs) = p[2];
  m(kAs, kAc) = -p[3];
  m(kAs, kAs) = p[1];
  m(kBs, kBc) = -p[3];
  m(kBs, kBs) = p[1];
  return m;
}

void CorrectionMatrixEstimator::add(const ChannelVector& z, const ChannelVector& zm) {
  // (E - P) z - zm = 0  <=>  P z = z - zm; P z is linear in p with these rows (one per channel).
  Eigen::Matrix4d j;
  j << z[kAc], 0.0, z[kAs], 0.0, z[kBc], 0.0, z[kBs], 0.0, 0.0, z[kAs], 0.0, -z[kAc], 0.0, z[kBs], 0.0, -z[kBc];
  const Eigen::Vector4d y = z - zm;
  jtj_.noalias() += j.transpose() * j;
  jty_.noalias() += j.transpose() * y;
  yty_ += y.squaredNorm();
  ++pairs_;
}

CorrectionMatrixEstimator::Result CorrectionMatrixEstimator::solve(double max_condition) const {
  Result r;
  r.pairs = pairs_;
  if (pairs_ < 2) {
    r.reason = "need at least 2 generator pairs, have " + std::to_string(pairs_);
    return r;
  }
  const LeastSquaresSolution fit = solveNormalEquations(jtj_, jty_, ColumnScaling::kNone, max_condition);
  r.condition_number = fit.condition_number;
  if (!fit.ok) {
    r.reason = "generator sweep does not determine p1..p4 (condition number " + std::to_string(r.condition_number) +
               "): spread theta over [0, pi)";
    return r;
  }
  const Eigen::VectorXd& p = fit.coefficients;
  const double rss = residualSquaresFromNormal(yty_, jtj_, jty_, p);
  const std::size_t channels = 4 * pairs_;
  const Eigen::MatrixXd cov = residualCovariance(fit.normal_inverse, residualVariance(rss, channels, 4));
  r.residual_rms = std::sqrt(rss / static_cast<double>(channels));
  for (int i = 0; i < 4; ++i) {
    r.correction.p[i] = p[i];
    r.standard_error[i] = std::sqrt(std::max(0.0, cov(i, i)));
  }
  r.ok = std::isfinite(p.sum());
  if (!r.ok) r.reason = "non-finite solution";
  return r;
}

}  // namespace core
}  // namespace hrg_gyro
