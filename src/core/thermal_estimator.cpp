#include "hrg_gyro/core/thermal_estimator.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Dense>

#include "hrg_gyro/core/units.h"

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
void designRow(const Layout& layout, const std::vector<int>& orders, const ThetaBinnedRates& rates, int b,
               double rate, double frequency, const FrequencyInterpolator& interpolator, std::vector<double>* weights,
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

/// The node's coefficients of one model, restricted to `wanted` orders, with standard errors.
HarmonicFitResult nodeFit(const Layout& layout, const std::vector<int>& orders, const std::vector<int>& wanted,
                          int model, std::size_t node, const Eigen::VectorXd& c, const Eigen::MatrixXd& cov) {
  HarmonicFitResult r;
  r.ok = true;
  r.orders = wanted;
  auto value = [&](std::size_t term) { return c[layout.column(model, term, node)]; };
  auto sd = [&](std::size_t term) {
    const std::size_t i = layout.column(model, term, node);
    return std::sqrt(std::max(0.0, cov(i, i)));
  };
  r.mean = value(0);
  r.mean_std = sd(0);
  for (int k : wanted) {
    const std::size_t q = static_cast<std::size_t>(std::find(orders.begin(), orders.end(), k) - orders.begin());
    r.cos.push_back(value(1 + q));
    r.sin.push_back(value(1 + layout.harmonics + q));
    r.cos_std.push_back(sd(1 + q));
    r.sin_std.push_back(sd(1 + layout.harmonics + q));
  }
  return r;
}

}  // namespace

ThermalEstimate estimateThermal(const RateGroup& group1, double rate1, const RateGroup& group2,
                                double rate2, const FrequencyInterpolator& interpolator, int bins,
                                const std::vector<int>& k_orders, const std::vector<int>& d_orders,
                                double min_bin_time, double max_condition) {
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
  const Layout layout{orders.size(), 1 + 2 * orders.size(), interpolator.size()};
  const std::size_t p = layout.columns();
  const RateGroup* groups[2] = {&group1, &group2};
  const double rates[2] = {rate1, rate2};
  std::vector<double> weights(layout.nodes), basis(layout.terms);

  // Design blocks, one per (group, slice): the bins' noise is correlated within a block only.
  struct Block {
    Eigen::MatrixXd x, v;
    Eigen::VectorXd y, w;
  };
  std::vector<Block> blocks;
  std::size_t n = 0;
  for (int g = 0; g < 2; ++g) {
    for (const auto& kv : groups[g]->slices) {
      const ThetaBinnedRates& r = kv.second;
      const std::vector<int> used = usedBins(r, min_bin_time);
      if (used.empty()) continue;
      Block blk;
      const Eigen::Index m = static_cast<Eigen::Index>(used.size());
      blk.x = Eigen::MatrixXd::Zero(m, static_cast<Eigen::Index>(p));
      blk.y.resize(m);
      blk.w.resize(m);
      std::vector<double> row(p);
      for (Eigen::Index i = 0; i < m; ++i) {
        designRow(layout, orders, r, used[i], rates[g], r.binTag(used[i]), interpolator, &weights, &basis, row.data());
        for (std::size_t c = 0; c < p; ++c) blk.x(i, static_cast<Eigen::Index>(c)) = row[c];
        blk.y[i] = r.binRate(used[i]);
        blk.w[i] = r.binTime(used[i]);
      }
      blk.v = r.rateCovariance(used);
      for (int k : orders) {
        const double s = sinc(0.5 * k * r.windowSpan());
        e.smoothing_factor = std::min(e.smoothing_factor, s * s);
      }
      n += used.size();
      blocks.push_back(std::move(blk));
    }
  }
  e.rows = n;
  if (n <= p) {
    e.reason = "need more than " + std::to_string(p) + " binned rates for " + std::to_string(p) +
               " node values, have " + std::to_string(n);
    return e;
  }

  // Normal equations, columns scaled to unit norm for the conditioning (K columns carry the
  // table rate, D columns do not).
  Eigen::MatrixXd a = Eigen::MatrixXd::Zero(p, p);
  Eigen::VectorXd rhs = Eigen::VectorXd::Zero(p);
  for (const Block& blk : blocks) {
    const Eigen::MatrixXd xw = blk.x.transpose() * blk.w.asDiagonal();
    a.noalias() += xw * blk.x;
    rhs.noalias() += xw * blk.y;
  }
  Eigen::VectorXd scale(p);
  for (std::size_t c = 0; c < p; ++c) {
    if (!(a(c, c) > 0.0)) {
      const std::size_t node = c % layout.nodes;
      e.reason = "no data constrain frequency node " + std::to_string(node) + " (" +
                 std::to_string(interpolator.nodes()[node]) + " Hz)";
      return e;
    }
    scale[c] = 1.0 / std::sqrt(a(c, c));
  }
  const Eigen::MatrixXd scaled = scale.asDiagonal() * a * scale.asDiagonal();
  // The scaled normal matrix is symmetric positive (semi)definite: its singular values are its
  // eigenvalues, the squares of the design matrix's singular values.
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(scaled, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Eigen::VectorXd sv = svd.singularValues();
  e.condition_number = sv[p - 1] > 0.0 ? std::sqrt(sv[0] / sv[p - 1]) : INFINITY;
  if (!(e.condition_number <= max_condition)) {
    e.reason = "ill-conditioned frequency-dependent fit (condition number " + std::to_string(e.condition_number) +
               "): the data do not separate the frequency nodes and harmonics";
    return e;
  }
  const Eigen::MatrixXd scaled_inverse = svd.matrixV() * sv.cwiseInverse().asDiagonal() * svd.matrixU().transpose();
  const Eigen::MatrixXd a_inverse = scale.asDiagonal() * scaled_inverse * scale.asDiagonal();
  const Eigen::VectorXd c = a_inverse * rhs;

  // Standard errors: the sandwich with each block's telescoped-bin covariance, plus the scatter
  // beyond it that is statistically significant, as independent noise of variance lambda / w.
  double weighted_ss = 0.0, predicted = 0.0;
  for (const Block& blk : blocks) {
    const Eigen::VectorXd r = blk.y - blk.x * c;
    weighted_ss += (blk.w.array() * r.array().square()).sum();
    predicted += (blk.w.array() * blk.v.diagonal().array()).sum();
  }
  const double dof = static_cast<double>(n - p);
  const double sigma2 = weighted_ss / dof;
  predicted /= static_cast<double>(n);
  const double excess = std::max(0.0, sigma2 - predicted * (1.0 + 3.0 * std::sqrt(2.0 / dof)));
  Eigen::MatrixXd meat = Eigen::MatrixXd::Zero(p, p);
  for (const Block& blk : blocks) {
    Eigen::MatrixXd v = blk.v;
    for (Eigen::Index i = 0; i < v.rows(); ++i) v(i, i) += excess / blk.w[i];
    const Eigen::MatrixXd xw = blk.x.transpose() * blk.w.asDiagonal();
    meat.noalias() += xw * v * xw.transpose();
  }
  const Eigen::MatrixXd cov = a_inverse * meat * a_inverse;
  if (!std::isfinite(c.sum()) || !std::isfinite(cov.sum())) {
    e.reason = "non-finite frequency-dependent fit";
    return e;
  }

  // Per-node results and the models.
  auto model = [&](int which, const std::vector<int>& wanted) {
    Eigen::MatrixXd values(1 + 2 * wanted.size(), layout.nodes);
    for (std::size_t j = 0; j < layout.nodes; ++j) {
      const HarmonicFitResult f = nodeFit(layout, orders, wanted, which, j, c, cov);
      const std::vector<double> terms = f.terms();
      for (std::size_t t = 0; t < terms.size(); ++t) values(static_cast<Eigen::Index>(t), j) = terms[t];
      (which == 0 ? e.k : e.d).push_back(f);
    }
    return HarmonicModel(wanted, interpolator, values);
  };
  e.k_model = model(0, k_orders);
  e.d_model = model(1, d_orders);

  // Dual-rate pairing by theta bin. On a ramp the two rates rarely share a slice, so each group's
  // bins are first moved to the middle frequency of the nodes with the fitted frequency dependence
  // (r - model(f_bin) + model(f_mid)) and summed over the slices; the paired K and D are then the
  // data at f_mid, and their scatter about the model (seen the same way) is the fit's residual.
  const double dr = rate1 - rate2;
  const double f_mid = 0.5 * (interpolator.nodes().front() + interpolator.nodes().back());
  struct Sum {
    double time = 0.0, rate = 0.0, model = 0.0;  // sum t, sum t (r moved to f_mid), sum t model(f_mid)
  };
  std::vector<Sum> sums[2] = {std::vector<Sum>(bins), std::vector<Sum>(bins)};
  std::vector<double> row(p), row_mid(p);
  for (int g = 0; g < 2; ++g) {
    for (const auto& kv : groups[g]->slices) {
      const ThetaBinnedRates& r = kv.second;
      for (int b : usedBins(r, min_bin_time)) {
        designRow(layout, orders, r, b, rates[g], r.binTag(b), interpolator, &weights, &basis, row.data());
        designRow(layout, orders, r, b, rates[g], f_mid, interpolator, &weights, &basis, row_mid.data());
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
    e.binned.push_back(pt);
  }
  const double paired = static_cast<double>(e.binned.size());
  e.k_residual_rms = paired > 0 ? std::sqrt(k_ss / paired) : 0.0;
  e.d_residual_rms = paired > 0 ? std::sqrt(d_ss / paired) : 0.0;
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
