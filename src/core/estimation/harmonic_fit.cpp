#include "hrg_gyro/core/estimation/harmonic_fit.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

#include "hrg_gyro/core/common/units.h"
#include "hrg_gyro/core/common/weighted_least_squares.h"

namespace hrg_gyro {
namespace core {

std::vector<double> HarmonicFitResult::terms() const {
  std::vector<double> t{mean};
  t.insert(t.end(), cos.begin(), cos.end());
  t.insert(t.end(), sin.begin(), sin.end());
  return t;
}

std::vector<double> HarmonicFitResult::termStds() const {
  std::vector<double> t{mean_std};
  t.insert(t.end(), cos_std.begin(), cos_std.end());
  t.insert(t.end(), sin_std.begin(), sin_std.end());
  return t;
}

HarmonicModel toModel(const HarmonicFitResult& fit) { return HarmonicModel(fit.orders, fit.mean, fit.cos, fit.sin); }

std::vector<int> mergeOrders(const std::vector<int>& a, const std::vector<int>& b) {
  std::vector<int> out(a);
  out.insert(out.end(), b.begin(), b.end());
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

HarmonicFitResult selectOrders(const HarmonicFitResult& fit, const std::vector<int>& orders) {
  HarmonicFitResult r = fit;
  r.orders = orders;
  r.cos.clear();
  r.sin.clear();
  r.cos_std.clear();
  r.sin_std.clear();
  for (int k : orders) {
    const auto it = std::find(fit.orders.begin(), fit.orders.end(), k);
    const bool found = it != fit.orders.end();
    const std::size_t j = static_cast<std::size_t>(it - fit.orders.begin());
    r.cos.push_back(found ? fit.cos[j] : 0.0);
    r.sin.push_back(found ? fit.sin[j] : 0.0);
    r.cos_std.push_back(found ? fit.cos_std[j] : 0.0);
    r.sin_std.push_back(found ? fit.sin_std[j] : 0.0);
  }
  return r;
}

HarmonicFitResult fitHarmonics(const std::vector<FitPoint>& points, const std::vector<int>& orders,
                               const std::vector<double>& extra_attenuation, double max_condition,
                               const Eigen::MatrixXd* value_covariance) {
  HarmonicFitResult r;
  r.orders = orders;
  const std::size_t n = points.size(), h = orders.size(), p = 1 + 2 * h;
  r.points = n;
  r.cos.assign(h, 0.0);
  r.sin.assign(h, 0.0);
  r.cos_std.assign(h, 0.0);
  r.sin_std.assign(h, 0.0);
  if (n <= p) {
    r.reason = "need more than " + std::to_string(p) + " points for " + std::to_string(h) + " harmonics, have " +
               std::to_string(n);
    return r;
  }
  Eigen::MatrixXd x(n, p);
  Eigen::VectorXd y(n), sw(n);
  for (std::size_t i = 0; i < n; ++i) {
    const FitPoint& pt = points[i];
    if (!(pt.weight > 0.0) || !std::isfinite(pt.value) || !std::isfinite(pt.theta)) {
      r.reason = "invalid fit point " + std::to_string(i);
      return r;
    }
    if (!pt.averaged_basis.empty() && pt.averaged_basis.size() != h) {
      r.reason = "fit point " + std::to_string(i) + " has a basis of the wrong size";
      return r;
    }
    x(i, 0) = 1.0;
    for (std::size_t j = 0; j < h; ++j) {
      const int k = orders[j];
      const double extra = extra_attenuation.empty() ? 1.0 : extra_attenuation[j];
      if (pt.averaged_basis.empty()) {
        const double att = sinc(0.5 * k * pt.span) * extra;
        r.smallest_attenuation = std::min(r.smallest_attenuation, std::abs(att));
        x(i, 1 + j) = att * std::cos(k * pt.theta);
        x(i, 1 + h + j) = att * std::sin(k * pt.theta);
      } else {
        r.smallest_attenuation = std::min(r.smallest_attenuation, std::abs(extra));
        x(i, 1 + j) = extra * pt.averaged_basis[j].first;
        x(i, 1 + h + j) = extra * pt.averaged_basis[j].second;
      }
    }
    y[i] = pt.value;
    sw[i] = std::sqrt(pt.weight);
  }
  const Eigen::MatrixXd a = sw.asDiagonal() * x;
  const Eigen::VectorXd b = sw.asDiagonal() * y;
  const LeastSquaresSolution fit = solveWeightedDesign(a, b, max_condition);
  r.condition_number = fit.condition_number;
  if (!fit.ok) {
    r.reason = "ill-conditioned harmonic fit (condition number " + std::to_string(r.condition_number) +
               "): the points do not cover theta well enough for these orders";
    return r;
  }
  const Eigen::VectorXd& c = fit.coefficients;
  const Eigen::VectorXd residual = y - x * c;
  const double sigma2 = residualVariance(fit.residual_squares, n, p);
  Eigen::MatrixXd cov;
  if (value_covariance && value_covariance->rows() == static_cast<Eigen::Index>(n)) {
    const Eigen::VectorXd w = (sw.array() * sw.array()).matrix();
    cov = sandwichCovariance(fit.normal_inverse, {{&x, &w, value_covariance}}, sigma2, p);
  } else {
    cov = residualCovariance(fit.normal_inverse, sigma2);
  }
  r.residual_rms = std::sqrt(residual.squaredNorm() / static_cast<double>(n));
  r.mean = c[0];
  r.mean_std = std::sqrt(std::max(0.0, cov(0, 0)));
  for (std::size_t j = 0; j < h; ++j) {
    r.cos[j] = c[1 + j];
    r.sin[j] = c[1 + h + j];
    r.cos_std[j] = std::sqrt(std::max(0.0, cov(1 + j, 1 + j)));
    r.sin_std[j] = std::sqrt(std::max(0.0, cov(1 + h + j, 1 + h + j)));
  }
  r.ok = std::isfinite(c.sum());
  if (!r.ok) r.reason = "non-finite fit";
  return r;
}

}  // namespace core
}  // namespace hrg_gyro
