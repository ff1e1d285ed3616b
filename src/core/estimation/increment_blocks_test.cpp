// The block store: merging neighbours keeps the sums and the block count; the sandwich is the
// cluster formula.
#include "hrg_gyro/core/estimation/increment_blocks.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <random>

namespace hrg_gyro {
namespace core {
namespace {

WindowIncrement randomIncrement(std::mt19937_64* random, int columns, double t_mid) {
  std::normal_distribution<double> normal(0.0, 1.0);
  WindowIncrement inc;
  inc.dw = Eigen::VectorXd(columns + 1);
  for (int i = 0; i <= columns; ++i) inc.dw(i) = normal(*random);
  inc.dt = 0.5;
  inc.t_mid = t_mid;
  inc.count_before = inc.count_after = 500.0;
  return inc;
}

TEST(IncrementBlocksTest, MergingNeighboursKeepsTheSumsAndThirtyTwoToSixtyFourBlocks) {
  const int columns = 5;
  IncrementBlocks store(columns);
  std::mt19937_64 random(8);
  Eigen::MatrixXd products = Eigen::MatrixXd::Zero(columns + 1, columns + 1);
  Eigen::VectorXd sum = Eigen::VectorXd::Zero(columns + 1);
  const Eigen::VectorXd no_prefix = Eigen::VectorXd::Zero(columns + 1);
  double time = 0.0;
  for (int n = 1; n <= 5000; ++n) {
    const WindowIncrement inc = randomIncrement(&random, columns, 0.5 * n);
    store.add(inc, no_prefix, no_prefix);
    products += inc.dw * inc.dw.transpose();
    sum += inc.dw;
    time += inc.dt;
    if (n >= 32 * 8 * 2) {  // past the first merges: always 32..64 blocks (the open one beside them)
      const std::size_t blocks = store.blocks().size();
      ASSERT_GE(blocks, 32u) << n;
      ASSERT_LE(blocks, 64u) << n;
    }
  }
  const std::vector<IncrementBlock> blocks = store.blocks();
  std::size_t count = 0;
  Eigen::VectorXd block_sum = Eigen::VectorXd::Zero(columns + 1);
  double block_time = 0.0;
  for (const IncrementBlock& b : blocks) {
    count += b.count;
    block_sum += b.sum;
    block_time += b.time;
  }
  EXPECT_EQ(count, 5000u);
  EXPECT_GT(store.blockSize(), 8u);  // merged
  EXPECT_LT((IncrementBlocks::total(blocks) - products).cwiseAbs().maxCoeff(), 1e-9 * products.cwiseAbs().maxCoeff());
  EXPECT_LT((block_sum - sum).cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_DOUBLE_EQ(block_time, time);
}

TEST(IncrementBlocksTest, TheMergedBlocksKeepTheWalksSelfSum) {
  // self = sum over the block's pairs of dt_i dt_j min(t_i, t_j): merging must add the cross terms.
  IncrementBlocks store(1);
  std::mt19937_64 random(2);
  const Eigen::VectorXd no_prefix = Eigen::VectorXd::Zero(2);
  std::vector<double> times;
  for (int n = 1; n <= 64 * 8; ++n) {  // the 64th block closes: the first merge
    store.add(randomIncrement(&random, 1, 0.5 * n), no_prefix, no_prefix);
    times.push_back(0.5 * n);
  }
  const std::vector<IncrementBlock> blocks = store.blocks();
  ASSERT_EQ(blocks.size(), 32u);
  const std::size_t per_block = blocks[0].count;
  ASSERT_EQ(per_block, 16u);
  double direct = 0.0;
  for (std::size_t i = 0; i < per_block; ++i)
    for (std::size_t j = 0; j < per_block; ++j) direct += 0.5 * 0.5 * std::min(times[i], times[j]);
  EXPECT_NEAR(blocks[0].self, direct, 1e-9 * direct);
}

TEST(IncrementBlocksTest, SandwichIsTheClusterFormulaWithNeighbours) {
  // Four blocks, two columns: inv (sum_c s_c s_c^T + s_c s_{c+1}^T + s_{c+1} s_c^T) inv, scaled by
  // g/(g-1) (n-1)/(n-p).
  const int columns = 2;
  IncrementBlocks store(columns);
  std::mt19937_64 random(6);
  const Eigen::VectorXd no_prefix = Eigen::VectorXd::Zero(columns + 1);
  std::vector<WindowIncrement> all;
  for (int n = 1; n <= 32; ++n) {
    all.push_back(randomIncrement(&random, columns, 0.5 * n));
    store.add(all.back(), no_prefix, no_prefix);
  }
  const std::vector<IncrementBlock> blocks = store.blocks();
  ASSERT_EQ(blocks.size(), 4u);
  const std::vector<int> sel = {0, 1};
  const Eigen::MatrixXd total = IncrementBlocks::total(blocks);
  LeastSquaresSolution solution;
  solution.normal_inverse = total.topLeftCorner(2, 2).inverse();
  solution.coefficients = solution.normal_inverse * total.block(0, 2, 2, 1);
  const Eigen::MatrixXd identity = Eigen::MatrixXd::Identity(columns + 1, columns + 1);
  const Eigen::MatrixXd sandwich = IncrementBlocks::sandwich(blocks, sel, identity, solution, columns, all.size());
  // Direct: each block's score sum x_i (y_i - x_i beta) over its increments.
  std::vector<Eigen::Vector2d> scores(4, Eigen::Vector2d::Zero());
  for (std::size_t i = 0; i < all.size(); ++i) {
    const Eigen::Vector2d x = all[i].dw.head(2);
    scores[i / 8] += x * (all[i].dw(2) - x.dot(solution.coefficients));
  }
  Eigen::Matrix2d meat = Eigen::Matrix2d::Zero();
  for (int c = 0; c < 4; ++c) {
    meat += scores[c] * scores[c].transpose();
    if (c < 3) meat += scores[c] * scores[c + 1].transpose() + scores[c + 1] * scores[c].transpose();
  }
  const Eigen::Matrix2d direct = (4.0 / 3.0) * (31.0 / 30.0) * solution.normal_inverse * meat * solution.normal_inverse;
  EXPECT_LT((sandwich - direct).cwiseAbs().maxCoeff(), 1e-12 * direct.cwiseAbs().maxCoeff());
}

}  // namespace
}  // namespace core
}  // namespace hrg_gyro
