#include "hrg_gyro/core/estimation/bias_random_walk.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

#include "hrg_gyro/core/estimation/increment_model.h"

namespace hrg_gyro {
namespace core {

BiasRandomWalk::BiasRandomWalk(int columns) : m_(columns) {
  prefix_ = prefix_integral_ = prefix_v_ = Eigen::VectorXd::Zero(m_ + 1);
  products_ = arw_products_ = Eigen::MatrixXd::Zero(m_ + 1, m_ + 1);
}

void BiasRandomWalk::add(const Eigen::VectorXd& dw, double dt, double t_mid) {
  // A bias walk b(t) leaves this increment dt b(t_mid): the prefix sums of its covariances.
  if (started_) {
    const double ds = t_mid - time_;
    prefix_integral_ += ds * prefix_;
    products_.noalias() += ds * prefix_ * prefix_.transpose();
  }
  started_ = true;
  time_ = t_mid;
  prefix_ += dt * dw;
  prefix_v_ += dt * t_mid * dw;
  arw_products_.noalias() += dt * dw * dw.transpose();
}

Eigen::MatrixXd BiasRandomWalk::scoreCovariance() const {
  // integral over [0, last] of (U - P)(U - P)^T ds, U the whole sum (P = 0 before the first increment).
  const Eigen::VectorXd& u = prefix_;
  const Eigen::VectorXd& integral = prefix_integral_;
  return u * u.transpose() * time_ - u * integral.transpose() - integral * u.transpose() + products_;
}

Eigen::MatrixXd BiasRandomWalk::covariance(const BiasWalkFit& walk, const std::vector<int>& sel,
                                           const Eigen::MatrixXd& map, const Eigen::MatrixXd& inverse) const {
  const double q2 = walk.rate_random_walk * walk.rate_random_walk;
  const double n2 = walk.angle_random_walk * walk.angle_random_walk;
  const Eigen::MatrixXd meat = map * (q2 * scoreCovariance() + n2 * arw_products_) * map.transpose();
  return inverse * selectedSubmatrix(meat, sel, sel) * inverse;
}

BiasWalkFit BiasRandomWalk::estimate(const std::vector<IncrementBlock>& blocks, const std::vector<int>& sel,
                                     const Eigen::MatrixXd& map, const LeastSquaresSolution& solution) const {
  std::vector<const IncrementBlock*> used;
  for (const IncrementBlock& b : blocks)
    if (b.time > 0.0) used.push_back(&b);
  if (used.size() < 8) return BiasWalkFit();
  return fitMoments(moments(used, sel, map, solution));
}

BiasRandomWalk::Moments BiasRandomWalk::moments(const std::vector<const IncrementBlock*>& used,
                                                const std::vector<int>& sel, const Eigen::MatrixXd& map,
                                                const LeastSquaresSolution& solution) const {
  // The blocks' residual sums r = s - X_b beta, s the sums of the increments' errors and X_b the
  // blocks' regressor sums. Their covariance for a unit bias walk and for a unit angle random walk,
  // exactly through the fit (which takes much of a walk into K, D and the trend):
  //   Cov(r) = C_ss - X_b inv C_xs - (X_b inv C_xs)^T + X_b inv C_xx inv X_b^T.
  const int g = static_cast<int>(used.size()), p = static_cast<int>(sel.size());
  const Eigen::MatrixXd& inverse = solution.normal_inverse;
  const Eigen::VectorXd& beta = solution.coefficients;
  auto selected = [&](const Eigen::VectorXd& raw) {
    const Eigen::VectorXd w = map * raw;
    Eigen::VectorXd out(p);
    for (int i = 0; i < p; ++i) out(i) = w(sel[i]);
    return out;
  };
  Eigen::MatrixXd xb(g, p), cxs_walk(p, g), cxs_arw(p, g);
  Eigen::MatrixXd css_walk = Eigen::MatrixXd::Zero(g, g), css_arw = Eigen::MatrixXd::Zero(g, g);
  Eigen::VectorXd r(g);
  for (int k = 0; k < g; ++k) {
    const IncrementBlock& b = *used[k];
    const Eigen::VectorXd w = map * b.sum;
    xb.row(k) = selected(b.sum).transpose();
    r(k) = w(m_) - xb.row(k).dot(beta);
    cxs_walk.col(k) = selected(b.prefix_v - b.prefix_p + prefix_ * b.moment);
    cxs_arw.col(k) = selected(b.sum_dt);
    css_walk(k, k) = b.self;
    css_arw(k, k) = b.time;
    for (int j = 0; j < k; ++j) css_walk(j, k) = css_walk(k, j) = used[j]->moment * b.time;
  }
  const Eigen::MatrixXd full_walk = map * scoreCovariance() * map.transpose();
  const Eigen::MatrixXd full_arw = map * arw_products_ * map.transpose();
  auto residualCovariance = [&](const Eigen::MatrixXd& css, const Eigen::MatrixXd& cxs, const Eigen::MatrixXd& full) {
    const Eigen::MatrixXd projected = xb * inverse;
    const Eigen::MatrixXd cross = projected * cxs;
    return Eigen::MatrixXd(css - cross - cross.transpose() +
                           projected * selectedSubmatrix(full, sel, sel) * projected.transpose());
  };
  const Eigen::MatrixXd cov_walk = residualCovariance(css_walk, cxs_walk, full_walk);
  const Eigen::MatrixXd cov_arw = residualCovariance(css_arw, cxs_arw, full_arw);
  // Moment equations: the difference of the mean residual rates of neighbouring groups of 1, 2 and
  // 4 blocks, E[d^2] = q^2 v^T Cov_walk v + N^2 v^T Cov_arw v (v the difference's weights).
  Moments m;
  for (int scale = 1; scale <= 4; scale *= 2) {
    for (int first = 0; first + 2 * scale <= g; first += scale) {
      Eigen::VectorXd v = Eigen::VectorXd::Zero(g);
      double t1 = 0.0, t2 = 0.0;
      for (int k = first; k < first + scale; ++k) t1 += used[k]->time;
      for (int k = first + scale; k < first + 2 * scale; ++k) t2 += used[k]->time;
      for (int k = first; k < first + scale; ++k) v(k) = -1.0 / t1;
      for (int k = first + scale; k < first + 2 * scale; ++k) v(k) = 1.0 / t2;
      const double d = v.dot(r);
      m.d2.push_back(d * d);
      m.a.push_back(std::max(0.0, v.dot(cov_walk * v)));
      m.c.push_back(std::max(0.0, v.dot(cov_arw * v)));
    }
  }
  return m;
}

BiasWalkFit BiasRandomWalk::fitMoments(const Moments& m) {
  const std::vector<double>&d2 = m.d2, &a = m.a, &c = m.c;
  const std::size_t n = d2.size();
  BiasWalkFit walk;
  // Weighted least squares, the weights 1 / (2 E^2) of a chi-square of one degree from the previous
  // pass's prediction E (first pass: the mean square); N^2 dropped where it comes out negative.
  double q2 = 0.0, n2 = 0.0, q2_var = 0.0;
  double mean_square = 0.0;
  for (double v : d2) mean_square += v / n;
  if (!(mean_square > 0.0)) return walk;
  for (int pass = 0; pass < 4; ++pass) {
    Eigen::Matrix2d normal = Eigen::Matrix2d::Zero();
    Eigen::Vector2d rhs = Eigen::Vector2d::Zero();
    for (std::size_t i = 0; i < n; ++i) {
      const double e = pass == 0 ? mean_square : std::max(q2 * a[i] + n2 * c[i], 1e-3 * mean_square);
      const double weight = 1.0 / (2.0 * e * e);
      const Eigen::Vector2d row(a[i], c[i]);
      normal.noalias() += weight * row * row.transpose();
      rhs += weight * d2[i] * row;
    }
    const Eigen::Vector2d both = normal.ldlt().solve(rhs);
    if (both(1) >= 0.0 && normal.determinant() > 0.0) {
      q2 = both(0);
      n2 = both(1);
      q2_var = normal.inverse()(0, 0);
    } else {
      q2 = normal(0, 0) > 0.0 ? rhs(0) / normal(0, 0) : 0.0;
      n2 = 0.0;
      q2_var = normal(0, 0) > 0.0 ? 1.0 / normal(0, 0) : 0.0;
    }
    q2 = std::max(q2, 0.0);
  }
  if (!(q2 > 0.0) || !std::isfinite(q2)) return walk;
  walk.rate_random_walk = std::sqrt(q2);
  walk.rate_random_walk_std = std::sqrt(q2_var) / (2.0 * walk.rate_random_walk);
  walk.angle_random_walk = std::sqrt(n2);
  walk.carried = true;
  return walk;
}

}  // namespace core
}  // namespace hrg_gyro
