// The per-block sums of the window increments, their merge, and the covariance of the fit's
// coefficients that rests on them: the block sandwich, with the white-noise prediction as its floor.
//
// The regression's errors are local (window_chains.h), so a cluster sandwich over blocks of
// consecutive increments estimates the covariance without assuming white errors. Streaming, in
// memory that does not grow with the session: the products of the increments are summed per block
// (p^2 each); when the blocks exceed a bound, neighbours are merged (exactly: the sums add), so the
// covariance always rests on 32..64 blocks. Each block also keeps the sums the bias walk's
// estimate needs (bias_random_walk.h).
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <vector>

#include "hrg_gyro/core/common/weighted_least_squares.h"
#include "hrg_gyro/core/estimation/window_chains.h"

namespace hrg_gyro {
namespace core {

/// The sums of a block of consecutive increments, in the accumulated columns (w = (dz, dy)).
struct IncrementBlock {
  Eigen::MatrixXd products;  ///< sum w w^T of its increments
  Eigen::VectorXd sum;       ///< sum w: the block's residual at the solution
  double time = 0.0;         ///< s: sum of the increments' dt
  double moment = 0.0;       ///< sum of dt t (t the increment's mid time from the session's first sample)
  /// For the walk's covariances (t_i, dt_i, w_i the increments; P and V the session's prefix sums of
  /// w dt and w dt t up to and including each): sum w dt, sum dt V(t), sum dt t P(t), and
  /// sum_{i,j in the block} dt_i dt_j min(t_i, t_j).
  Eigen::VectorXd sum_dt, prefix_v, prefix_p;
  double self = 0.0;
  std::size_t count = 0;
};

class IncrementBlocks {
 public:
  /// Blocks are merged in pairs when they reach this many.
  static constexpr std::size_t kMaxBlocks = 64;

  /// columns: the model's (IncrementModel::columns()); the sums have one more, y.
  explicit IncrementBlocks(int columns);

  /// An increment, with the session's prefix sums P (of w dt) and V (of w dt t) up to and including it.
  void add(const WindowIncrement& increment, const Eigen::VectorXd& prefix_p, const Eigen::VectorXd& prefix_v);
  /// The closed blocks and the open one (if it holds any increment).
  std::vector<IncrementBlock> blocks() const;
  /// Increments per closed block (doubles at each merge).
  std::size_t blockSize() const { return block_size_; }
  /// Every increment's w w^T.
  static Eigen::MatrixXd total(const std::vector<IncrementBlock>& blocks);

  /// The block sandwich of the solution of columns `sel` (mapped by `map`; y is column `y_column`)
  /// over `increments` increments, with the products of neighbouring blocks' scores.
  static Eigen::MatrixXd sandwich(const std::vector<IncrementBlock>& blocks, const std::vector<int>& sel,
                                  const Eigen::MatrixXd& map, const LeastSquaresSolution& solution, int y_column,
                                  std::size_t increments);
  /// What white wave-angle noise of `angle_noise` rad per sample alone predicts for the coefficients.
  Eigen::MatrixXd white(const std::vector<int>& sel, const Eigen::MatrixXd& map, const Eigen::MatrixXd& inverse,
                        double angle_noise) const;

 private:
  void mergeNeighbours();

  int m_;
  std::vector<IncrementBlock> blocks_;
  IncrementBlock open_;
  std::size_t block_size_ = 8;
  Eigen::MatrixXd white_lag0_, white_lag1_;  // predicted white-noise products, per unit variance
  Eigen::VectorXd previous_dz_;              // last increment of the chain, for the lag-one products
};

}  // namespace core
}  // namespace hrg_gyro
