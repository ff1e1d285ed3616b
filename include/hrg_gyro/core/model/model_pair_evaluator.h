// Evaluates a scale-factor model K and a drift model D together at (theta, f): one sincos and one
// recurrence serve both, and the coefficients are re-interpolated only when the frequency changes.
// Used by the compensator (measured models) and by the simulator's dynamics (intrinsic models).
#pragma once

#include <cmath>
#include <vector>

#include "hrg_gyro/core/model/harmonic_model.h"

namespace hrg_gyro {
namespace core {

class ModelPairEvaluator {
 public:
  /// Keeps pointers to both models: they must outlive the evaluator (the compensator keeps them in
  /// a shared parameter set, so moving the evaluator around is safe).
  ModelPairEvaluator(const HarmonicModel& k, const HarmonicModel& d);

  bool frequencyDependent() const { return frequency_dependent_; }

  /// K(theta, f) and D(theta, f).
  void evaluate(double theta, double frequency, double* k, double* d) {
    const bool same = frequency == cached_frequency_ || (std::isnan(frequency) && cached_is_nan_);
    if (frequency_dependent_ && !same) refresh(frequency);
    basis_.evaluate(theta);
    *k = k_->evaluate(basis_, k_coefficients_.data());
    *d = d_->evaluate(basis_, d_coefficients_.data());
  }
  /// The same with c2 = cos 2 theta and s2 = sin 2 theta supplied (the per-sample path).
  void evaluate(double theta, double c2, double s2, double frequency, double* k, double* d) {
    const bool same = frequency == cached_frequency_ || (std::isnan(frequency) && cached_is_nan_);
    if (frequency_dependent_ && !same) refresh(frequency);
    basis_.evaluate(theta, c2, s2);
    *k = k_->evaluate(basis_, k_coefficients_.data());
    *d = d_->evaluate(basis_, d_coefficients_.data());
  }

 private:
  void refresh(double frequency);

  const HarmonicModel* k_;
  const HarmonicModel* d_;
  HarmonicBasis basis_;
  std::vector<double> k_coefficients_, d_coefficients_;
  bool frequency_dependent_;
  double cached_frequency_ = 0.0;
  bool cached_is_nan_ = false;
};

}  // namespace core
}  // namespace hrg_gyro
