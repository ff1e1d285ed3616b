#include "hrg_gyro/core/estimation/increment_model.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>

#include "hrg_gyro/core/estimation/wave_angle_noise.h"

namespace hrg_gyro {
namespace core {
namespace {

constexpr int kMaxTrendOrder = 2;

int orderStep(const std::vector<int>& orders) {
  int g = 0;
  for (int k : orders) g = std::gcd(g, k);
  return g > 0 ? g : 1;
}

}  // namespace

Eigen::MatrixXd selectedSubmatrix(const Eigen::MatrixXd& m, const std::vector<int>& rows,
                                  const std::vector<int>& cols) {
  Eigen::MatrixXd out(rows.size(), cols.size());
  for (std::size_t i = 0; i < rows.size(); ++i)
    for (std::size_t j = 0; j < cols.size(); ++j) out(i, j) = m(rows[i], cols[j]);
  return out;
}

Eigen::VectorXd selectedColumn(const Eigen::MatrixXd& m, const std::vector<int>& rows, int col) {
  Eigen::VectorXd out(rows.size());
  for (std::size_t i = 0; i < rows.size(); ++i) out(i) = m(rows[i], col);
  return out;
}

IncrementModel::IncrementModel(const std::vector<int>& k_orders, const std::vector<int>& d_orders, int bias_trend_order,
                               int horizontal_slots)
    : k_orders_(k_orders),
      d_orders_(d_orders),
      all_orders_(mergeOrders(k_orders, d_orders)),
      trend_order_(bias_trend_order),
      horizontal_slots_(horizontal_slots) {
  for (int k : all_orders_)
    if (k <= 0) throw std::invalid_argument("increment regression: harmonic orders must be positive");
  if (trend_order_ < 0 || trend_order_ > kMaxTrendOrder)
    throw std::invalid_argument("increment regression: the bias trend order must be 0, 1 or 2");
  if (horizontal_slots_ < 0) throw std::invalid_argument("increment regression: horizontal slots must be >= 0");
  const int n_k = static_cast<int>(k_orders_.size()), n_all = static_cast<int>(all_orders_.size());
  horizontal0_ = 1 + 2 * n_k + 1 + 2 * n_all + trend_order_;
  m_ = horizontal0_ + 2 * horizontal_slots_;
  // Accumulated per sample: the regression's columns with the K block taken along the table angle,
  // then the same K block along the rate integral, then y.
  k_terms_ = 1 + 2 * n_k;
  rate_k0_ = m_;
  raw_y_ = m_ + k_terms_;
  for (int k : k_orders_) k_in_all_.push_back(orderIndex(k));
  // The T column of each K column's order (K0: T itself): b dt of the chain's slope correction.
  const int t0 = 1 + 2 * n_k;
  time_column_of_k_.push_back(t0);
  for (int j = 0; j < n_k; ++j) time_column_of_k_.push_back(t0 + 1 + k_in_all_[j]);
  for (int j = 0; j < n_k; ++j) time_column_of_k_.push_back(t0 + 1 + n_all + k_in_all_[j]);
}

int IncrementModel::orderIndex(int k) const {
  return static_cast<int>(std::lower_bound(all_orders_.begin(), all_orders_.end(), k) - all_orders_.begin());
}

HarmonicBasis IncrementModel::basis() const {
  return HarmonicBasis(orderStep(all_orders_), all_orders_.empty() ? 0 : all_orders_.back());
}

void IncrementModel::integrate(const IncrementStep& step, Eigen::VectorXd* integrals) const {
  const int n_k = static_cast<int>(k_orders_.size()), n_all = static_cast<int>(all_orders_.size());
  const int t0 = 1 + 2 * n_k;
  const Eigen::VectorXd &c = *step.cos_now, &s = *step.sin_now;
  const Eigen::VectorXd &cos_prev = *step.cos_before, &sin_prev = *step.sin_before;
  Eigen::VectorXd& out = *integrals;
  const double dt = step.dt, dphi = step.dphi;
  out(0) += dphi;
  for (int j = 0; j < n_k; ++j) {
    const int u = k_in_all_[j];
    out(1 + j) += 0.5 * (c(u) + cos_prev(u)) * dphi;
    out(1 + n_k + j) += 0.5 * (s(u) + sin_prev(u)) * dphi;
  }
  if (step.has_rate) {
    const double drate = step.drate;
    out(rate_k0_) += drate;
    for (int j = 0; j < n_k; ++j) {
      const int u = k_in_all_[j];
      out(rate_k0_ + 1 + j) += 0.5 * (c(u) + cos_prev(u)) * drate;
      out(rate_k0_ + 1 + n_k + j) += 0.5 * (s(u) + sin_prev(u)) * drate;
    }
  }
  out(t0) += dt;
  for (int u = 0; u < n_all; ++u) {
    out(t0 + 1 + u) += 0.5 * (c(u) + cos_prev(u)) * dt;
    out(t0 + 1 + n_all + u) += 0.5 * (s(u) + sin_prev(u)) * dt;
  }
  // The trend's integrals of t^j dt, exact (a polynomial needs no trapezoid).
  double now_power = step.t_session, before_power = step.t_session_before;
  for (int j = 1; j <= trend_order_; ++j) {
    now_power *= step.t_session;
    before_power *= step.t_session_before;
    out(t0 + 1 + 2 * n_all + j - 1) += (now_power - before_power) / (j + 1);
  }
}

void IncrementModel::integrateHorizontal(int slot, double psi, double psi_before, double dt,
                                         Eigen::VectorXd* integrals) const {
  const int col = horizontal0_ + 2 * slot;
  (*integrals)(col) += 0.5 * (std::cos(psi) + std::cos(psi_before)) * dt;
  (*integrals)(col + 1) += 0.5 * (std::sin(psi) + std::sin(psi_before)) * dt;
}

Eigen::MatrixXd IncrementModel::regressorMap(double earth_rate, double reference_time) const {
  const int n_k = static_cast<int>(k_orders_.size()), n_all = static_cast<int>(all_orders_.size());
  const int t0 = 1 + 2 * n_k, trend0 = t0 + 1 + 2 * n_all;
  Eigen::MatrixXd map = Eigen::MatrixXd::Identity(m_ + 1, m_ + 1);
  // The Earth rate enters phi as earth_rate * t, so each K regressor gains earth_rate times the T
  // regressor of the same order.
  map(0, t0) = earth_rate;
  for (int j = 0; j < n_k; ++j) {
    map(1 + j, t0 + 1 + orderIndex(k_orders_[j])) = earth_rate;
    map(1 + n_k + j, t0 + 1 + n_all + orderIndex(k_orders_[j])) = earth_rate;
  }
  // The trend's integrals of t^j dt become those of (t - t_ref)^j dt: the binomial expansion over
  // the lower powers (power 0 is the T column).
  for (int j = 1; j <= trend_order_; ++j) {
    double binomial = 1.0;  // C(j, i), from i = 0
    for (int i = 0; i < j; ++i) {
      map(trend0 + j - 1, i == 0 ? t0 : trend0 + i - 1) = binomial * std::pow(-reference_time, j - i);
      binomial = binomial * (j - i) / (i + 1);
    }
  }
  return map;
}

IncrementColumns IncrementModel::fittedColumns(const std::vector<bool>& slot_seen) const {
  const int n_k = static_cast<int>(k_orders_.size()), n_all = static_cast<int>(all_orders_.size());
  const int t0 = 1 + 2 * n_k, n_kterms = 1 + 2 * n_k, trend0 = t0 + 1 + 2 * n_all;
  IncrementColumns c;
  for (int j = 0; j < n_kterms; ++j) c.sel.push_back(j);
  c.sel.push_back(t0);
  for (int k : d_orders_) c.sel.push_back(t0 + 1 + orderIndex(k));
  for (int k : d_orders_) c.sel.push_back(t0 + 1 + n_all + orderIndex(k));
  c.without_trend = c.sel;
  c.trend_at = static_cast<int>(c.sel.size());
  for (int j = 0; j < trend_order_; ++j) c.sel.push_back(trend0 + j);
  c.horizontal_at = static_cast<int>(c.sel.size());
  for (int slot = 0; slot < horizontal_slots_; ++slot) {
    if (!slot_seen[slot]) continue;  // no data: the columns are zero
    c.horizontal.push_back(slot);
    for (int j = 0; j < 2; ++j) {
      c.sel.push_back(horizontal0_ + 2 * slot + j);
      c.without_trend.push_back(horizontal0_ + 2 * slot + j);
    }
  }
  return c;
}

LeastSquaresSolution IncrementModel::solve(const std::vector<int>& sel, const Eigen::MatrixXd& map,
                                           const Eigen::MatrixXd& total, double max_condition) const {
  const Eigen::MatrixXd s = map * total * map.transpose();
  return solveNormalEquations(selectedSubmatrix(s, sel, sel), selectedColumn(s, sel, m_), ColumnScaling::kUnitNorm,
                              max_condition);
}

Eigen::VectorXd IncrementModel::earthRateShift(const std::vector<int>& sel, const Eigen::VectorXd& beta,
                                               const Eigen::MatrixXd& total, double earth_rate, double earth_rate_std,
                                               double reference_time, double max_condition) const {
  const int p = static_cast<int>(sel.size());
  Eigen::VectorXd earth_shift = Eigen::VectorXd::Zero(p);
  if (earth_rate_std > 0.0) {
    const Eigen::MatrixXd s = regressorMap(earth_rate + earth_rate_std, reference_time) * total *
                              regressorMap(earth_rate + earth_rate_std, reference_time).transpose();
    const LeastSquaresSolution moved = solveNormalEquations(selectedSubmatrix(s, sel, sel), selectedColumn(s, sel, m_),
                                                            ColumnScaling::kUnitNorm, max_condition);
    if (moved.ok) earth_shift = (moved.coefficients - beta).cwiseAbs();
  }
  return earth_shift;
}

IncrementTerms IncrementModel::correctedTerms(const Eigen::VectorXd& beta, const IncrementCovariances& covariances,
                                              const Eigen::VectorXd& earth_shift, double angle_noise,
                                              IncrementFit* fit) const {
  const int n_k = static_cast<int>(k_orders_.size()), n_d = static_cast<int>(d_orders_.size());
  const int n_kterms = 1 + 2 * n_k;
  const Eigen::MatrixXd& sandwich = covariances.sandwich;
  const Eigen::MatrixXd& white = covariances.white;
  const Eigen::MatrixXd& walk = covariances.walk;
  const int p = static_cast<int>(beta.size());
  std::vector<double> scale(p, 1.0);
  for (int j = 0; j < n_k; ++j)
    scale[1 + j] = scale[1 + n_k + j] = WaveAngleNoise::attenuation(k_orders_[j], angle_noise);
  for (int j = 0; j < n_d; ++j)
    scale[n_kterms + 1 + j] = scale[n_kterms + 1 + n_d + j] = WaveAngleNoise::attenuation(d_orders_[j], angle_noise);

  IncrementTerms terms;
  terms.value.resize(p);
  terms.total_std.resize(p);
  for (int i = 0; i < p; ++i) {
    terms.value[i] = beta(i) * scale[i];
    const double statistical = std::sqrt(std::max(sandwich(i, i), white(i, i) + walk(i, i))) * scale[i];
    const double noise = std::sqrt(std::max(0.0, white(i, i))) * scale[i];
    const double beyond = std::sqrt(std::max(0.0, sandwich(i, i) - white(i, i))) * scale[i];
    const double earth = earth_shift(i);
    const double basis = WaveAngleNoise::correctionUncertainty(beta(i), scale[i]);
    terms.total_std[i] = std::sqrt(statistical * statistical + earth * earth + basis * basis);
    IncrementErrorBudget* part =
        i < n_kterms ? &fit->budget : (i < n_kterms + 1 + 2 * n_d ? &fit->drift_budget : nullptr);
    if (part) {
      part->statistical.push_back(statistical);
      part->angle_noise.push_back(noise);
      part->beyond_noise.push_back(beyond);
      part->earth_rate.push_back(earth);
      part->basis_noise.push_back(basis);
      part->bias_walk.push_back(std::sqrt(std::max(0.0, walk(i, i))) * scale[i]);
    }
  }
  return terms;
}

void IncrementModel::fillFit(const IncrementTerms& terms, const std::vector<int>& orders, int offset,
                             double condition_number, std::size_t points, HarmonicFitResult* f) {
  const int h = static_cast<int>(orders.size());
  f->ok = true;
  f->orders = orders;
  f->mean = terms.value[offset];
  f->mean_std = terms.total_std[offset];
  for (int j = 0; j < h; ++j) {
    f->cos.push_back(terms.value[offset + 1 + j]);
    f->cos_std.push_back(terms.total_std[offset + 1 + j]);
    f->sin.push_back(terms.value[offset + 1 + h + j]);
    f->sin_std.push_back(terms.total_std[offset + 1 + h + j]);
  }
  f->condition_number = condition_number;
  f->points = points;
}

void IncrementModel::fitTrend(const IncrementColumns& columns, const IncrementTerms& terms,
                              const LeastSquaresSolution& solution, const Eigen::MatrixXd& map,
                              const Eigen::MatrixXd& total, double reference_time, Nanoseconds session_origin,
                              double span, BiasTrendFit* trend) const {
  const int trend_at = columns.trend_at;
  trend->order = trend_order_;
  for (int j = 0; j < trend_order_; ++j) {
    trend->coefficients.push_back(terms.value[trend_at + j]);
    trend->stds.push_back(terms.total_std[trend_at + j]);
  }
  trend->reference_time = reference_time;
  trend->reference_stamp = session_origin + toNanoseconds(reference_time);
  trend->span = span;
  // How the design confuses the trend with K0, from its geometry alone (the normal inverse): the
  // same fit without the trend, and the correlation of K0 with the linear term.
  const LeastSquaresSolution without =
      solve(columns.without_trend, map, total, std::numeric_limits<double>::infinity());
  const Eigen::MatrixXd& inv = solution.normal_inverse;
  if (without.ok && without.normal_inverse(0, 0) > 0.0) {
    trend->k0_inflation = std::sqrt(inv(0, 0) / without.normal_inverse(0, 0));
  }
  trend->k0_correlation = inv(0, trend_at) / std::sqrt(inv(0, 0) * inv(trend_at, trend_at));
}

}  // namespace core
}  // namespace hrg_gyro
