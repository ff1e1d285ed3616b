// Weighted least-squares fit of M(theta) = m0 + sum_k a_k cos k theta + b_k sin k theta to points
// that are averages of M over an angle span (bins, windows, steps), with standard errors.
//
// A point averaged uniformly over [theta - s/2, theta + s/2] sees harmonic k attenuated by
// sinc(k s / 2); the design matrix carries that factor (and an optional per-order extra factor such
// as the window smoothing), so the fitted coefficients are those of M itself, not of its smoothed
// version.
//
// Standard errors: without a noise model, from the residual scatter (cov = sigma^2 (X^T W X)^-1,
// sigma^2 = sum w r^2 / (n - p)), which assumes independent points. When the points' noise is
// correlated (telescoped bin rates are), the caller passes its predicted covariance V and the
// sandwich A^-1 X^T W V W X A^-1 (A = X^T W X) is used; scatter beyond what V predicts is added as
// independent noise (proportional to 1/w), so the errors never understate the data.
#pragma once

#include <Eigen/Core>
#include <string>
#include <utility>
#include <vector>

#include "hrg_gyro/core/model/harmonic_model.h"

namespace hrg_gyro {
namespace core {

struct FitPoint {
  double theta = 0.0;  ///< rad, centre of the span
  double value = 0.0;
  double weight = 1.0;  ///< relative, > 0
  double span = 0.0;    ///< rad over which the value is an average
  /// Optional, replaces theta and span: the mean of (cos k theta, sin k theta) over what the value
  /// averages, one pair per fitted order.
  std::vector<std::pair<double, double>> averaged_basis;
};

struct HarmonicFitResult {
  bool ok = false;
  std::string reason;
  std::vector<int> orders;
  double mean = 0.0, mean_std = 0.0;
  std::vector<double> cos, sin, cos_std, sin_std;
  double residual_rms = 0.0;      ///< of value - fitted (attenuated) model, unweighted
  double condition_number = 0.0;  ///< of the weighted design matrix
  std::size_t points = 0;
  /// Smallest attenuation applied to any fitted harmonic (1 = none).
  double smallest_attenuation = 1.0;

  /// The coefficient vector in HarmonicModel term order (mean, cos..., sin...).
  std::vector<double> terms() const;
  std::vector<double> termStds() const;
};

/// extra_attenuation: one factor per order (empty = none). max_condition: refuse worse fits.
HarmonicFitResult fitHarmonics(const std::vector<FitPoint>& points, const std::vector<int>& orders,
                               const std::vector<double>& extra_attenuation = {}, double max_condition = 1e8,
                               const Eigen::MatrixXd* value_covariance = nullptr);

/// The fit restricted to `orders`, in that order: their coefficients and standard errors (zeros for
/// an order the fit lacks); the mean and the fit's statistics are kept.
HarmonicFitResult selectOrders(const HarmonicFitResult& fit, const std::vector<int>& orders);

/// The frequency-independent model of a fit (only the given orders, in that order).
HarmonicModel toModel(const HarmonicFitResult& fit);

/// Union of two order sets, sorted.
std::vector<int> mergeOrders(const std::vector<int>& a, const std::vector<int>& b);

}  // namespace core
}  // namespace hrg_gyro
