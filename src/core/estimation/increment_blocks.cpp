#include "hrg_gyro/core/estimation/increment_blocks.h"

#include "hrg_gyro/core/estimation/increment_model.h"

namespace hrg_gyro {
namespace core {

IncrementBlocks::IncrementBlocks(int columns) : m_(columns) {
  open_.products = Eigen::MatrixXd::Zero(m_ + 1, m_ + 1);
  open_.sum = open_.sum_dt = open_.prefix_v = open_.prefix_p = Eigen::VectorXd::Zero(m_ + 1);
  white_lag0_ = white_lag1_ = Eigen::MatrixXd::Zero(m_, m_);
}

void IncrementBlocks::add(const WindowIncrement& increment, const Eigen::VectorXd& prefix_p,
                          const Eigen::VectorXd& prefix_v) {
  const Eigen::VectorXd& dw = increment.dw;
  const double dt = increment.dt, t_mid = increment.t_mid;
  open_.products.noalias() += dw * dw.transpose();
  open_.self += 2.0 * dt * open_.moment + dt * dt * t_mid;  // the earlier increments are older
  open_.sum += dw;
  open_.sum_dt += dt * dw;
  open_.prefix_v += dt * prefix_v;
  open_.prefix_p += dt * t_mid * prefix_p;
  open_.time += dt;
  open_.moment += dt * t_mid;
  if (++open_.count >= block_size_) {
    blocks_.push_back(open_);
    open_.products.setZero();
    open_.sum.setZero();
    open_.sum_dt.setZero();
    open_.prefix_v.setZero();
    open_.prefix_p.setZero();
    open_.time = open_.moment = open_.self = 0.0;
    open_.count = 0;
    if (blocks_.size() >= kMaxBlocks) mergeNeighbours();
  }
  // White wave-angle noise of variance v per sample: a window mean of n samples has v / n; the
  // increment b - a has v (1/n_a + 1/n_b) and shares -v / n_a with the increment before it.
  const Eigen::VectorXd dz = dw.head(m_);
  white_lag0_.noalias() += (1.0 / increment.count_before + 1.0 / increment.count_after) * dz * dz.transpose();
  if (increment.follows) white_lag1_.noalias() += (1.0 / increment.count_before) * dz * previous_dz_.transpose();
  previous_dz_ = dz;
}

void IncrementBlocks::mergeNeighbours() {
  // The sums add, so this is the same data in half as many, longer blocks.
  std::vector<IncrementBlock> merged;
  for (std::size_t i = 0; i + 1 < blocks_.size(); i += 2) {
    IncrementBlock m = blocks_[i];
    const IncrementBlock& next = blocks_[i + 1];
    m.products += next.products;
    m.self += next.self + 2.0 * next.time * m.moment;  // every increment of m is older
    m.sum += next.sum;
    m.sum_dt += next.sum_dt;
    m.prefix_v += next.prefix_v;
    m.prefix_p += next.prefix_p;
    m.time += next.time;
    m.moment += next.moment;
    m.count += next.count;
    merged.push_back(m);
  }
  if (blocks_.size() % 2) merged.push_back(blocks_.back());
  blocks_.swap(merged);
  block_size_ *= 2;
}

std::vector<IncrementBlock> IncrementBlocks::blocks() const {
  std::vector<IncrementBlock> out = blocks_;
  if (open_.count > 0) out.push_back(open_);
  return out;
}

Eigen::MatrixXd IncrementBlocks::total(const std::vector<IncrementBlock>& blocks) {
  const Eigen::Index n = blocks.empty() ? 0 : blocks.front().products.rows();
  Eigen::MatrixXd total = Eigen::MatrixXd::Zero(n, n);
  for (const IncrementBlock& b : blocks) total += b.products;
  return total;
}

Eigen::MatrixXd IncrementBlocks::sandwich(const std::vector<IncrementBlock>& blocks, const std::vector<int>& sel,
                                          const Eigen::MatrixXd& map, const LeastSquaresSolution& solution,
                                          int y_column, std::size_t increments) {
  const Eigen::VectorXd& beta = solution.coefficients;
  const Eigen::MatrixXd& inverse = solution.normal_inverse;
  const int p = static_cast<int>(sel.size());
  // The score of each block at the solution. Neighbouring blocks share the window mean at their
  // boundary (with opposite signs), and that shared term is most of a block's score for white angle
  // noise, so the products of neighbouring scores are kept as well (a lag-one block estimate); blocks
  // further apart share nothing.
  std::vector<Eigen::VectorXd> scores;
  for (const IncrementBlock& b : blocks) {
    const Eigen::MatrixXd sb = map * b.products * map.transpose();
    scores.push_back(selectedColumn(sb, sel, y_column) - selectedSubmatrix(sb, sel, sel) * beta);
  }
  Eigen::MatrixXd meat = Eigen::MatrixXd::Zero(p, p);
  for (std::size_t c = 0; c < scores.size(); ++c) {
    meat.noalias() += scores[c] * scores[c].transpose();
    if (c + 1 < scores.size()) {
      const Eigen::MatrixXd cross = scores[c] * scores[c + 1].transpose();
      meat += cross + cross.transpose();
    }
  }
  const double g = static_cast<double>(blocks.size()), n = static_cast<double>(increments);
  return (g / (g - 1.0)) * ((n - 1.0) / (n - p)) * inverse * meat * inverse;
}

Eigen::MatrixXd IncrementBlocks::white(const std::vector<int>& sel, const Eigen::MatrixXd& map,
                                       const Eigen::MatrixXd& inverse, double angle_noise) const {
  // A floor: a few blocks can understate by chance.
  const Eigen::MatrixXd zmap = map.topLeftCorner(m_, m_);
  const Eigen::MatrixXd white_full =
      zmap * (white_lag0_ - white_lag1_ - white_lag1_.transpose()) * zmap.transpose() * (angle_noise * angle_noise);
  return inverse * selectedSubmatrix(white_full, sel, sel) * inverse;
}

}  // namespace core
}  // namespace hrg_gyro
