#include "hrg_gyro/core/harmonic_fit.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Dense>

#include "hrg_gyro/core/units.h"

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
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(a);
  const Eigen::VectorXd sv = svd.singularValues();
  r.condition_number = sv(sv.size() - 1) > 0.0 ? sv(0) / sv(sv.size() - 1) : INFINITY;
  if (!(r.condition_number <= max_condition)) {
    r.reason = "ill-conditioned harmonic fit (condition number " + std::to_string(r.condition_number) +
               "): the points do not cover theta well enough for these orders";
    return r;
  }
  const Eigen::VectorXd c = a.colPivHouseholderQr().solve(b);
  const Eigen::VectorXd weighted_residual = b - a * c;
  const Eigen::VectorXd residual = y - x * c;
  const double sigma2 = weighted_residual.squaredNorm() / static_cast<double>(n - p);
  const Eigen::MatrixXd a_inv = (a.transpose() * a).inverse();
  Eigen::MatrixXd cov = sigma2 * a_inv;
  if (value_covariance && value_covariance->rows() == static_cast<Eigen::Index>(n)) {
    Eigen::MatrixXd v = *value_covariance;
    // Scatter beyond the model's prediction, as independent noise of variance lambda / w: only the
    // part above the chance level of the scatter itself (3 sigma of its chi-square fluctuation), so
    // that chance does not inflate the errors of the harmonics the correlated noise barely reaches.
    double predicted = 0.0;
    for (std::size_t i = 0; i < n; ++i) predicted += sw[i] * sw[i] * v(i, i);
    predicted /= static_cast<double>(n);
    const double significant = predicted * (1.0 + 3.0 * std::sqrt(2.0 / static_cast<double>(n - p)));
    const double lambda = std::max(0.0, sigma2 - significant);  // continuous: no jump at the threshold
    for (std::size_t i = 0; i < n; ++i) v(i, i) += lambda / (sw[i] * sw[i]);
    const Eigen::MatrixXd xw = x.transpose() * (sw.array() * sw.array()).matrix().asDiagonal();
    cov = a_inv * (xw * v * xw.transpose()) * a_inv;
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
