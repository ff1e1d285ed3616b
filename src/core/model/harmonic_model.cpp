#include "hrg_gyro/core/model/harmonic_model.h"

#include <algorithm>
#include <numeric>
#include <stdexcept>

#include "hrg_gyro/core/common/units.h"

namespace hrg_gyro {
namespace core {

HarmonicModel::HarmonicModel(double mean) : values_(Eigen::MatrixXd::Constant(1, 1, mean)) {}

HarmonicModel::HarmonicModel(std::vector<int> orders, double mean, const std::vector<double>& cos,
                             const std::vector<double>& sin)
    : orders_(std::move(orders)) {
  const std::size_t n = orders_.size();
  if (cos.size() != n || sin.size() != n) {
    throw std::invalid_argument("harmonic model: need one cos and one sin coefficient per order");
  }
  values_.resize(termCount(), 1);
  values_(0, 0) = mean;
  for (std::size_t i = 0; i < n; ++i) {
    values_(1 + i, 0) = cos[i];
    values_(1 + n + i, 0) = sin[i];
  }
  for (int k : orders_) {
    if (k < 1) throw std::invalid_argument("harmonic model: orders must be positive");
  }
}

HarmonicModel::HarmonicModel(std::vector<int> orders, FrequencyInterpolator interpolator, Eigen::MatrixXd node_values)
    : orders_(std::move(orders)), interpolator_(std::move(interpolator)), values_(std::move(node_values)) {
  if (static_cast<std::size_t>(values_.rows()) != termCount() ||
      static_cast<std::size_t>(values_.cols()) != interpolator_.size()) {
    throw std::invalid_argument("harmonic model: node values must be (1 + 2 orders) x nodes");
  }
  for (int k : orders_) {
    if (k < 1) throw std::invalid_argument("harmonic model: orders must be positive");
  }
}

int HarmonicModel::maxOrder() const { return orders_.empty() ? 0 : *std::max_element(orders_.begin(), orders_.end()); }

int HarmonicModel::orderStep() const {
  int g = 0;
  for (int k : orders_) g = std::gcd(g, k);
  return g;
}

void HarmonicModel::coefficientsAt(double frequency, double* out) const {
  const Eigen::Index terms = values_.rows();
  if (values_.cols() == 1) {
    for (Eigen::Index t = 0; t < terms; ++t) out[t] = values_(t, 0);
    return;
  }
  double w[64];
  std::vector<double> heap;
  double* wp = w;
  if (interpolator_.size() > 64) {
    heap.resize(interpolator_.size());
    wp = heap.data();
  }
  interpolator_.weights(frequency, wp);
  for (Eigen::Index t = 0; t < terms; ++t) {
    double v = 0.0;
    for (Eigen::Index j = 0; j < values_.cols(); ++j) v += wp[j] * values_(t, j);
    out[t] = v;
  }
}

double HarmonicModel::meanAt(double frequency) const {
  std::vector<double> c(termCount());
  coefficientsAt(frequency, c.data());
  return c[0];
}

double HarmonicModel::operator()(double theta, double frequency) const {
  std::vector<double> c(termCount());
  coefficientsAt(frequency, c.data());
  const int step = std::max(1, orderStep());
  HarmonicBasis basis(step, maxOrder());
  basis.evaluate(theta);
  return evaluate(basis, c.data());
}

double HarmonicModel::peakDeviation(double frequency) const {
  if (orders_.empty()) return 0.0;
  std::vector<double> c(termCount());
  coefficientsAt(frequency, c.data());
  c[0] = 0.0;  // deviation from the mean
  HarmonicBasis basis(std::max(1, orderStep()), maxOrder());
  // 64 points per period of the highest harmonic resolve the peak to ~1e-3 relative.
  const int points = std::max(256, 64 * maxOrder());
  double peak = 0.0;
  for (int i = 0; i < points; ++i) {
    basis.evaluate(kTwoPi * i / points);
    peak = std::max(peak, std::abs(evaluate(basis, c.data())));
  }
  return peak;
}

}  // namespace core
}  // namespace hrg_gyro
