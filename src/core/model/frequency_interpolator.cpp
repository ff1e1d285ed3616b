#include "hrg_gyro/core/model/frequency_interpolator.h"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace hrg_gyro {
namespace core {

const char* toString(Interpolation kind) {
  return kind == Interpolation::kPiecewiseLinear ? "piecewise_linear" : "natural_cubic_spline";
}

bool parseInterpolation(const std::string& text, Interpolation* kind) {
  if (text == "natural_cubic_spline") {
    *kind = Interpolation::kNaturalCubicSpline;
  } else if (text == "piecewise_linear") {
    *kind = Interpolation::kPiecewiseLinear;
  } else {
    return false;
  }
  return true;
}

FrequencyInterpolator::FrequencyInterpolator(std::vector<double> nodes, Interpolation kind)
    : nodes_(std::move(nodes)), kind_(kind) {
  if (nodes_.empty()) throw std::invalid_argument("at least one frequency node is required");
  for (std::size_t j = 0; j < nodes_.size(); ++j) {
    if (!std::isfinite(nodes_[j]))
      throw std::invalid_argument("frequency node " + std::to_string(j) + " is not finite");
    if (j > 0 && !(nodes_[j] > nodes_[j - 1])) {
      throw std::invalid_argument("frequency nodes must be strictly increasing (node " + std::to_string(j) + ")");
    }
  }
  const int n = static_cast<int>(nodes_.size());
  curvature_ = Eigen::MatrixXd::Zero(n, n);
  if (kind_ != Interpolation::kNaturalCubicSpline || n < 3) return;
  // Interior equations of the natural spline: T m = D y, with m_0 = m_{n-1} = 0.
  Eigen::MatrixXd t = Eigen::MatrixXd::Zero(n - 2, n - 2);
  Eigen::MatrixXd d = Eigen::MatrixXd::Zero(n - 2, n);
  for (int i = 1; i < n - 1; ++i) {
    const double h0 = nodes_[i] - nodes_[i - 1], h1 = nodes_[i + 1] - nodes_[i];
    const int r = i - 1;
    if (r > 0) t(r, r - 1) = h0;
    t(r, r) = 2.0 * (h0 + h1);
    if (r < n - 3) t(r, r + 1) = h1;
    d(r, i - 1) = 6.0 / h0;
    d(r, i) = -6.0 / h0 - 6.0 / h1;
    d(r, i + 1) = 6.0 / h1;
  }
  curvature_.block(1, 0, n - 2, n) = t.inverse() * d;
}

void FrequencyInterpolator::weights(double f, double* w) const {
  const std::size_t n = nodes_.size();
  std::fill(w, w + n, 0.0);
  if (n == 1 || !std::isfinite(f) || f <= nodes_.front()) {
    w[0] = 1.0;
    return;
  }
  if (f >= nodes_.back()) {
    w[n - 1] = 1.0;
    return;
  }
  const std::size_t i =
      static_cast<std::size_t>(std::upper_bound(nodes_.begin(), nodes_.end(), f) - nodes_.begin()) - 1;
  const double h = nodes_[i + 1] - nodes_[i];
  const double t = (f - nodes_[i]) / h;
  w[i] = 1.0 - t;
  w[i + 1] = t;
  if (kind_ != Interpolation::kNaturalCubicSpline || n < 3) return;
  const double ci = h * h / 6.0 * ((1.0 - t) * (1.0 - t) * (1.0 - t) - (1.0 - t));
  const double cj = h * h / 6.0 * (t * t * t - t);
  for (std::size_t k = 0; k < n; ++k) w[k] += ci * curvature_(i, k) + cj * curvature_(i + 1, k);
}

}  // namespace core
}  // namespace hrg_gyro
