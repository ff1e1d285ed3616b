// Test support: how far a calibrated model is from the exact one. The residual a compensation with
// the estimate leaves (its nonlinearity with the K0 offset apart, and that offset), the largest
// standard error of its harmonics, and the worst error of a fit's coefficients in its own reported
// standard errors.
#pragma once

#include <algorithm>
#include <cmath>

#include "hrg_gyro/core/common/units.h"
#include "hrg_gyro/core/estimation/harmonic_fit.h"
#include "hrg_gyro/core/model/harmonic_model.h"

namespace hrg_gyro {
namespace core {
namespace testing {

/// ppm of |K0| of the truth.
struct ModelResidual {
  double nonlinearity_ppm = 0.0;  ///< peak over theta of |K_est - K_true - (K0_est - K0_true)|
  double scale_ppm = 0.0;         ///< K0_est - K0_true
};

/// `estimate` at frequency `estimate_frequency` against `truth` at `truth_frequency` (NaN: a model
/// that does not depend on it), the peak taken over `points` angles evenly in [0, pi).
inline ModelResidual residualAgainst(const HarmonicModel& estimate, double estimate_frequency,
                                     const HarmonicModel& truth, double truth_frequency, int points) {
  const double k0 = std::abs(truth.meanAt(truth_frequency));
  const double offset = estimate.meanAt(estimate_frequency) - truth.meanAt(truth_frequency);
  double peak = 0.0;
  for (int i = 0; i < points; ++i) {
    const double theta = kPi * i / points;
    peak = std::max(peak, std::abs(estimate(theta, estimate_frequency) - truth(theta, truth_frequency) - offset));
  }
  ModelResidual r;
  r.nonlinearity_ppm = 1e6 * peak / k0;
  r.scale_ppm = 1e6 * offset / k0;
  return r;
}

/// The largest standard error of a fit's harmonics, ppm of |K0|.
inline double maxHarmonicStdPpm(const HarmonicFitResult& k) {
  double m = 0.0;
  for (std::size_t j = 0; j < k.orders.size(); ++j) m = std::max({m, k.cos_std[j], k.sin_std[j]});
  return 1e6 * m / std::abs(k.mean);
}

/// Largest |estimate - reference| / sigma over the terms of a fit (sigmas the estimate's).
inline double worstNormalisedError(const HarmonicFitResult& estimate, const HarmonicFitResult& reference) {
  double worst = std::abs(estimate.mean - reference.mean) / estimate.mean_std;
  for (std::size_t j = 0; j < estimate.orders.size(); ++j) {
    worst = std::max(worst, std::abs(estimate.cos[j] - reference.cos[j]) / estimate.cos_std[j]);
    worst = std::max(worst, std::abs(estimate.sin[j] - reference.sin[j]) / estimate.sin_std[j]);
  }
  return worst;
}

}  // namespace testing
}  // namespace core
}  // namespace hrg_gyro
