// The bias random walk of the increment regression: its estimate from the fit's residuals, and the
// covariance it gives the fitted coefficients.
//
// A bias that follows a random walk (rate random walk q, rad/s/sqrt(s)) is what no polynomial
// follows: it leaves each increment an error dt_i b(t_i), correlated over the whole session, which
// the block sandwich (blocks share nothing beyond their neighbours, increment_blocks.h) does not see.
// The walk is estimated from the residuals: the mean residual rates of consecutive blocks (and of
// pairs and fours of them) differ by a variance q^2 a + N^2 c (N the angle random walk), a and c
// computed exactly through the fit, which takes much of a walk into K, D and the trend (a would be
// T1/3 + T2/3 + gap without it); a moment fit of q^2 and N^2 weighted by its own prediction. Where
// q^2 comes out positive, the fit's covariance carries the walk exactly:
//   Cov(X'e) = q^2 integral S(s) S(s)^T ds + N^2 sum x_i x_i^T dt_i,  S(s) = sum_{t_i > s} x_i dt_i,
// summed as the increments arrive (S from prefix sums, so memory stays fixed), and each coefficient's
// statistical variance is the larger of the sandwich and that model (with the white angle noise).
#pragma once

#include <Eigen/Core>
#include <vector>

#include "hrg_gyro/core/common/weighted_least_squares.h"
#include "hrg_gyro/core/estimation/increment_blocks.h"
#include "hrg_gyro/core/estimation/increment_fit.h"

namespace hrg_gyro {
namespace core {

class BiasRandomWalk {
 public:
  /// columns: the model's (IncrementModel::columns()); the sums have one more, y.
  explicit BiasRandomWalk(int columns);

  /// An increment's w (accumulated columns), dt and mid time (s from the session's first sample).
  void add(const Eigen::VectorXd& dw, double dt, double t_mid);
  /// P: the prefix sum of w dt over the increments so far.
  const Eigen::VectorXd& prefix() const { return prefix_; }
  /// V: the prefix sum of w dt t.
  const Eigen::VectorXd& prefixMoment() const { return prefix_v_; }

  /// q and N from the blocks' mean residual rates at the solution of columns `sel` (mapped by `map`).
  BiasWalkFit estimate(const std::vector<IncrementBlock>& blocks, const std::vector<int>& sel,
                       const Eigen::MatrixXd& map, const LeastSquaresSolution& solution) const;
  /// The covariance of the coefficients that the walk predicts (inverse: the normal inverse).
  Eigen::MatrixXd covariance(const BiasWalkFit& walk, const std::vector<int>& sel, const Eigen::MatrixXd& map,
                             const Eigen::MatrixXd& inverse) const;
  /// Cov(X^T e) for a unit bias walk from the session's start: integral of S S^T ds, S(s) the sum of
  /// w dt over the increments after s (raw columns).
  Eigen::MatrixXd scoreCovariance() const;
  /// The angle random walk's: sum of w w^T dt.
  const Eigen::MatrixXd& angleWalkProducts() const { return arw_products_; }

 private:
  /// The moment equations' squared differences d2 and their predictions a (unit walk), c (unit ARW).
  struct Moments {
    std::vector<double> d2, a, c;
  };
  Moments moments(const std::vector<const IncrementBlock*>& used, const std::vector<int>& sel,
                  const Eigen::MatrixXd& map, const LeastSquaresSolution& solution) const;
  /// q^2 and N^2 by weighted least squares on the moments.
  static BiasWalkFit fitMoments(const Moments& m);

  int m_;
  // P the prefix sum of w dt over the increments so far, A = integral of P ds and B = integral of
  // P P^T ds over their mid times, V the prefix sum of w dt t; the angle random walk's sum of w w^T dt.
  Eigen::VectorXd prefix_, prefix_integral_, prefix_v_;
  Eigen::MatrixXd products_, arw_products_;
  bool started_ = false;
  double time_ = 0.0;
};

}  // namespace core
}  // namespace hrg_gyro
