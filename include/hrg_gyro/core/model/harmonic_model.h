// The paper's unified model for the scale factor K and the drift D:
//   M(theta, f) = M0(f) + sum_{k in orders} a_k(f) cos(k theta) + b_k(f) sin(k theta)
// theta is the electrical wave angle; it is defined modulo pi, so physical models use even orders
// (the parameter file enforces that). Every coefficient is either a constant or given at frequency
// nodes and interpolated (FrequencyInterpolator).
//
// The coefficients are stored as a (terms x nodes) matrix, term 0 the mean, then the cos
// coefficients in the order of orders(), then the sin coefficients. Hot-path use: coefficientsAt(f)
// once per frequency change, HarmonicBasis::evaluate(theta) once per sample for all models, then
// evaluate(basis, coefficients) per model.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <vector>

#include "hrg_gyro/core/model/frequency_interpolator.h"
#include "hrg_gyro/core/model/harmonic_basis.h"

namespace hrg_gyro {
namespace core {

class HarmonicModel {
 public:
  /// Constant model (no harmonics).
  explicit HarmonicModel(double mean = 0.0);
  /// Frequency-independent model. cos and sin must have one value per order.
  HarmonicModel(std::vector<int> orders, double mean, const std::vector<double>& cos, const std::vector<double>& sin);
  /// Frequency-dependent model: node_values is (1 + 2 orders) x interpolator.size().
  HarmonicModel(std::vector<int> orders, FrequencyInterpolator interpolator, Eigen::MatrixXd node_values);

  const std::vector<int>& orders() const { return orders_; }
  std::size_t termCount() const { return 1 + 2 * orders_.size(); }
  bool frequencyDependent() const { return interpolator_.size() > 1; }
  const FrequencyInterpolator& interpolator() const { return interpolator_; }
  const Eigen::MatrixXd& nodeValues() const { return values_; }
  int maxOrder() const;
  /// Greatest common divisor of the orders (0 without harmonics).
  int orderStep() const;

  /// Coefficient values at frequency f (mean, cos..., sin...) into out[termCount()].
  void coefficientsAt(double frequency, double* out) const;
  /// Mean (M0) at frequency f.
  double meanAt(double frequency) const;

  /// M for a basis already evaluated at theta (its step must divide every order) and coefficients
  /// from coefficientsAt().
  double evaluate(const HarmonicBasis& basis, const double* coefficients) const {
    double m = coefficients[0];
    const std::size_t n = orders_.size();
    for (std::size_t i = 0; i < n; ++i) {
      m += coefficients[1 + i] * basis.cosOf(orders_[i]) + coefficients[1 + n + i] * basis.sinOf(orders_[i]);
    }
    return m;
  }

  /// Convenience evaluation (tests, tools; not the per-sample path).
  double operator()(double theta, double frequency = NAN) const;

  /// max over theta of |M(theta, f) - M0(f)| (dense grid over one turn).
  double peakDeviation(double frequency = NAN) const;

  bool operator==(const HarmonicModel& o) const {
    return orders_ == o.orders_ && interpolator_ == o.interpolator_ && values_ == o.values_;
  }
  bool operator!=(const HarmonicModel& o) const { return !(*this == o); }

 private:
  std::vector<int> orders_;
  FrequencyInterpolator interpolator_;
  Eigen::MatrixXd values_;
};

}  // namespace core
}  // namespace hrg_gyro
