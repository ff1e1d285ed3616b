#include "hrg_gyro/core/estimation/thermal_estimator.h"

#include <Eigen/Core>
#include <algorithm>
#include <cmath>

#include "hrg_gyro/core/common/units.h"
#include "hrg_gyro/core/common/weighted_least_squares.h"

namespace hrg_gyro {
namespace core {
namespace {

/// Columns of the joint fit: model (0 = K, 1 = D), term t (mean, cos..., sin...), node j.
struct Layout {
  std::size_t harmonics, terms, nodes;
  std::size_t column(int model, std::size_t term, std::size_t node) const {
    return (static_cast<std::size_t>(model) * terms + term) * nodes + node;
  }
  std::size_t columns() const { return 2 * terms * nodes; }
};

/// One design row: the bin b of one group's slice, with the model taken at `frequency` (the bin's
/// own mean frequency for the fit).
void designRow(const Layout& layout, const std::vector<int>& orders, const ThetaBinnedRates& rates, int b, double rate,
               double frequency, const FrequencyInterpolator& interpolator, std::vector<double>* weights,
               std::vector<double>* basis, double* row) {
  interpolator.weights(frequency, weights->data());
  const double span = rates.windowSpan();
  const std::size_t h = layout.harmonics;
  (*basis)[0] = 1.0;
  for (std::size_t q = 0; q < h; ++q) {
    const double s = sinc(0.5 * orders[q] * span);
    (*basis)[1 + q] = s * s * rates.basisMean(b, orders[q], false);
    (*basis)[1 + h + q] = s * s * rates.basisMean(b, orders[q], true);
  }
  for (std::size_t t = 0; t < layout.terms; ++t) {
    for (std::size_t j = 0; j < layout.nodes; ++j) {
      const double v = (*weights)[j] * (*basis)[t];
      row[layout.column(0, t, j)] = rate * v;
      row[layout.column(1, t, j)] = v;
    }
  }
}

std::vector<int> usedBins(const ThetaBinnedRates& rates, double min_bin_time) {
  std::vector<int> used;
  for (int b = 0; b < rates.binCount(); ++b) {
    if (rates.binTime(b) >= min_bin_time && rates.binTime(b) > 0.0) used.push_back(b);
  }
  return used;
}

/// The node's coefficients of one model over all fitted orders, with standard errors.
HarmonicFitResult nodeFit(const Layout& layout, const std::vector<int>& orders, int model, std::size_t node,
                          const Eigen::VectorXd& c, const Eigen::MatrixXd& cov) {
  HarmonicFitResult r;
  r.ok = true;
  r.orders = orders;
  auto value = [&](std::size_t term) { return c[layout.column(model, term, node)]; };
  auto sd = [&](std::size_t term) {
    const std::size_t i = layout.column(model, term, node);
    return std::sqrt(std::max(0.0, cov(i, i)));
  };
  r.mean = value(0);
  r.mean_std = sd(0);
  for (std::size_t q = 0; q < layout.harmonics; ++q) {
    r.cos.push_back(value(1 + q));
    r.sin.push_back(value(1 + layout.harmonics + q));
    r.cos_std.push_back(sd(1 + q));
    r.sin_std.push_back(sd(1 + layout.harmonics + q));
  }
  return r;
}

/// The design rows of one (group, slice): its bins' noise is correlated within the block only.
struct Block {
  Eigen::MatrixXd x, v;
  Eigen::VectorXd y, w;
};

/// What the joint fit works on: the two groups at their effective rates, the fitted orders and the
/// column layout.
struct JointProblem {
  const RateGroup* groups[2];
  double rates[2];
  std::vector<int> orders;
  Layout layout;
  const FrequencyInterpolator& interpolator;
  double min_bin_time;
};

/// Step 1: one design block per (group, slice) with used bins; the rows counted in e->rows and the
/// smallest window attenuation in e->smoothing_factor.
std::vector<Block> designBlocks(const JointProblem& jp, ThermalEstimate* e) {
  const std::size_t p = jp.layout.columns();
  std::vector<double> weights(jp.layout.nodes), basis(jp.layout.terms), row(p);
  std::vector<Block> blocks;
  std::size_t n = 0;
  for (int g = 0; g < 2; ++g) {
    for (const auto& kv : jp.groups[g]->slices) {
      const ThetaBinnedRates& r = kv.second;
      const std::vector<int> used = usedBins(r, jp.min_bin_time);
      if (used.empty()) continue;
      Block blk;
      const Eigen::Index m = static_cast<Eigen::Index>(used.size());
      blk.x = Eigen::MatrixXd::Zero(m, static_cast<Eigen::Index>(p));
      blk.y.resize(m);
      blk.w.resize(m);
      for (Eigen::Index i = 0; i < m; ++i) {
        designRow(jp.layout, jp.orders, r, used[i], jp.rates[g], r.binTag(used[i]), jp.interpolator, &weights, &basis,
                  row.data());
        for (std::size_t c = 0; c < p; ++c) blk.x(i, static_cast<Eigen::Index>(c)) = row[c];
        blk.y[i] = r.binRate(used[i]);
        blk.w[i] = r.binTime(used[i]);
      }
      blk.v = r.rateCovariance(used);
      for (int k : jp.orders) {
        const double s = sinc(0.5 * k * r.windowSpan());
        e->smoothing_factor = std::min(e->smoothing_factor, s * s);
      }
      n += used.size();
      blocks.push_back(std::move(blk));
    }
  }
  e->rows = n;
  return blocks;
}

/// Step 2: the normal equations over all blocks, solved with the columns scaled to unit norm (K
/// columns carry the table rate, D columns do not). False with e->reason when refused.
bool solveJoint(const JointProblem& jp, const std::vector<Block>& blocks, double max_condition,
                LeastSquaresSolution* fit, ThermalEstimate* e) {
  const std::size_t p = jp.layout.columns();
  Eigen::MatrixXd a = Eigen::MatrixXd::Zero(p, p);
  Eigen::VectorXd rhs = Eigen::VectorXd::Zero(p);
  for (const Block& blk : blocks) {
    const Eigen::MatrixXd xw = blk.x.transpose() * blk.w.asDiagonal();
    a.noalias() += xw * blk.x;
    rhs.noalias() += xw * blk.y;
  }
  for (std::size_t c = 0; c < p; ++c) {
    if (!(a(c, c) > 0.0)) {
      const std::size_t node = c % jp.layout.nodes;
      e->reason = "no data constrain frequency node " + std::to_string(node) + " (" +
                  std::to_string(jp.interpolator.nodes()[node]) + " Hz)";
      return false;
    }
  }
  *fit = solveNormalEquations(a, rhs, ColumnScaling::kUnitNorm, max_condition);
  e->condition_number = fit->condition_number;
  if (!fit->ok) {
    e->reason = "ill-conditioned frequency-dependent fit (condition number " + std::to_string(e->condition_number) +
                "): the data do not separate the frequency nodes and harmonics";
    return false;
  }
  return true;
}

/// Step 3: standard errors, the sandwich with each block's telescoped-bin covariance plus the
/// significant scatter beyond it.
Eigen::MatrixXd jointCovariance(const std::vector<Block>& blocks, const LeastSquaresSolution& fit, std::size_t n) {
  double weighted_ss = 0.0;
  std::vector<CorrelatedBlock> correlated;
  for (const Block& blk : blocks) {
    const Eigen::VectorXd r = blk.y - blk.x * fit.coefficients;
    weighted_ss += (blk.w.array() * r.array().square()).sum();
    correlated.push_back({&blk.x, &blk.w, &blk.v});
  }
  const std::size_t p = static_cast<std::size_t>(fit.coefficients.size());
  return sandwichCovariance(fit.normal_inverse, correlated, residualVariance(weighted_ss, n, p), p);
}

/// Step 4: per-node results of one model at its own orders, and the model over the nodes.
HarmonicModel nodeModel(const JointProblem& jp, int which, const std::vector<int>& wanted, const Eigen::VectorXd& c,
                        const Eigen::MatrixXd& cov, std::vector<HarmonicFitResult>* fits) {
  Eigen::MatrixXd values(1 + 2 * wanted.size(), jp.layout.nodes);
  for (std::size_t j = 0; j < jp.layout.nodes; ++j) {
    const HarmonicFitResult f = selectOrders(nodeFit(jp.layout, jp.orders, which, j, c, cov), wanted);
    const std::vector<double> terms = f.terms();
    for (std::size_t t = 0; t < terms.size(); ++t) values(static_cast<Eigen::Index>(t), j) = terms[t];
    fits->push_back(f);
  }
  return HarmonicModel(wanted, jp.interpolator, values);
}

/// Step 5: dual-rate pairing by theta bin. On a ramp the two rates rarely share a slice, so each
/// group's bins are first moved to the middle frequency of the nodes with the fitted frequency
/// dependence (r - model(f_bin) + model(f_mid)) and summed over the slices; the paired K and D are
/// then the data at f_mid, and their scatter about the model (seen the same way) is the fit's
/// residual (e->binned, e->k_residual_rms, e->d_residual_rms).
void pairBins(const JointProblem& jp, int bins, const Eigen::VectorXd& c, ThermalEstimate* e) {
  const std::size_t p = jp.layout.columns();
  const double rate1 = jp.rates[0], rate2 = jp.rates[1];
  const double dr = rate1 - rate2;
  const double f_mid = 0.5 * (jp.interpolator.nodes().front() + jp.interpolator.nodes().back());
  struct Sum {
    double time = 0.0, rate = 0.0, model = 0.0;  // sum t, sum t (r moved to f_mid), sum t model(f_mid)
  };
  std::vector<Sum> sums[2] = {std::vector<Sum>(bins), std::vector<Sum>(bins)};
  std::vector<double> weights(jp.layout.nodes), basis(jp.layout.terms), row(p), row_mid(p);
  for (int g = 0; g < 2; ++g) {
    for (const auto& kv : jp.groups[g]->slices) {
      const ThetaBinnedRates& r = kv.second;
      for (int b : usedBins(r, jp.min_bin_time)) {
        designRow(jp.layout, jp.orders, r, b, jp.rates[g], r.binTag(b), jp.interpolator, &weights, &basis, row.data());
        designRow(jp.layout, jp.orders, r, b, jp.rates[g], f_mid, jp.interpolator, &weights, &basis, row_mid.data());
        double m = 0.0, m_mid = 0.0;
        for (std::size_t col = 0; col < p; ++col) {
          m += row[col] * c[col];
          m_mid += row_mid[col] * c[col];
        }
        Sum& sum = sums[g][b];
        sum.time += r.binTime(b);
        sum.rate += r.binTime(b) * (r.binRate(b) - m + m_mid);
        sum.model += r.binTime(b) * m_mid;
      }
    }
  }
  double k_ss = 0.0, d_ss = 0.0;
  for (int b = 0; b < bins; ++b) {
    const Sum& s1 = sums[0][b];
    const Sum& s2 = sums[1][b];
    if (s1.time <= 0.0 || s2.time <= 0.0) continue;
    const double r1 = s1.rate / s1.time, r2 = s2.rate / s2.time;
    const double m1 = s1.model / s1.time, m2 = s2.model / s2.time;
    BinnedCurvePoint pt;
    pt.theta = (b + 0.5) * kPi / bins;
    pt.k = (r1 - r2) / dr;
    pt.d = (r2 * rate1 - r1 * rate2) / dr;
    pt.weight = std::min(s1.time, s2.time);
    const double k_fit = (m1 - m2) / dr, d_fit = (m2 * rate1 - m1 * rate2) / dr;
    k_ss += (pt.k - k_fit) * (pt.k - k_fit);
    d_ss += (pt.d - d_fit) * (pt.d - d_fit);
    e->binned.push_back(pt);
  }
  const double paired = static_cast<double>(e->binned.size());
  e->k_residual_rms = paired > 0 ? std::sqrt(k_ss / paired) : 0.0;
  e->d_residual_rms = paired > 0 ? std::sqrt(d_ss / paired) : 0.0;
}

}  // namespace

ThermalEstimate estimateThermal(const RateGroup& group1, double rate1, const RateGroup& group2, double rate2,
                                const FrequencyInterpolator& interpolator, int bins, const std::vector<int>& k_orders,
                                const std::vector<int>& d_orders, double min_bin_time, double max_condition) {
  ThermalEstimate e;
  if (!(std::abs(rate1 - rate2) > 0.0)) {
    e.reason = "the two plateau rates are equal";
    return e;
  }
  if (interpolator.size() < 2) {
    e.reason = "a frequency-dependent model needs at least 2 frequency nodes";
    return e;
  }
  const std::vector<int> orders = mergeOrders(k_orders, d_orders);
  const JointProblem jp{
      {&group1, &group2}, {rate1, rate2}, orders, Layout{orders.size(), 1 + 2 * orders.size(), interpolator.size()},
      interpolator,       min_bin_time};
  const std::size_t p = jp.layout.columns();
  const std::vector<Block> blocks = designBlocks(jp, &e);
  const std::size_t n = e.rows;
  if (n <= p) {
    e.reason = "need more than " + std::to_string(p) + " binned rates for " + std::to_string(p) +
               " node values, have " + std::to_string(n);
    return e;
  }
  LeastSquaresSolution fit;
  if (!solveJoint(jp, blocks, max_condition, &fit, &e)) return e;
  const Eigen::VectorXd& c = fit.coefficients;
  const Eigen::MatrixXd cov = jointCovariance(blocks, fit, n);
  if (!std::isfinite(c.sum()) || !std::isfinite(cov.sum())) {
    e.reason = "non-finite frequency-dependent fit";
    return e;
  }
  e.k_model = nodeModel(jp, 0, k_orders, c, cov, &e.k);
  e.d_model = nodeModel(jp, 1, d_orders, c, cov, &e.d);
  pairBins(jp, bins, c, &e);
  for (auto* fits : {&e.k, &e.d}) {
    for (HarmonicFitResult& f : *fits) {
      f.residual_rms = fits == &e.k ? e.k_residual_rms : e.d_residual_rms;
      f.condition_number = e.condition_number;
      f.points = n;
      f.smallest_attenuation = e.smoothing_factor;
    }
  }
  e.ok = true;
  return e;
}

}  // namespace core
}  // namespace hrg_gyro
