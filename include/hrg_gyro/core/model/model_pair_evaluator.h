// Evaluates a scale-factor model K and a drift model D together at (theta, f): one sincos and one
// recurrence serve both, and the coefficients are re-interpolated only when the frequency changes.
// Used by the compensator (measured models) and by the simulator's dynamics (intrinsic models).
#pragma once

#include <cmath>
#include <vector>

#include "hrg_gyro/core/common/double_lanes.h"
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
    if (frequency_dependent_) followFrequency(frequency);
    basis_.evaluate(theta);
    *k = sum(k_coefficients_.data(), k_indices_);
    *d = sum(d_coefficients_.data(), d_indices_);
  }
  /// The same with c2 = cos 2 theta and s2 = sin 2 theta supplied (the per-sample path): the orders'
  /// cos and sin follow by the recurrence in registers and both sums run beside it, every basis
  /// order present (a missing one has zero coefficients, which adds exactly nothing).
  void evaluate(double theta, double c2, double s2, double frequency, double* k, double* d) {
    if (frequency_dependent_) followFrequency(frequency);
    const int step = basis_.step();
    if (step % 2 != 0) {
      basis_.evaluate(theta);
      *k = sum(k_coefficients_.data(), k_indices_);
      *d = sum(d_coefficients_.data(), d_indices_);
      return;
    }
    double c1, s1;
    firstOrder(c2, s2, &c1, &s1);
    // Each model's cos and sin sums side by side in a pair of lanes, and the recurrence on (cos, sin)
    // as one complex product in lanes: (c, s) (c1, s1) = (c c1 + s (-s1), s c1 + c s1).
    DoubleLanes2 k_sums = {k_coefficients_[0], 0.0}, d_sums = {d_coefficients_[0], 0.0};
    DoubleLanes2 cs = {c1, s1};
    const DoubleLanes2 rotate_cos = {c1, c1}, rotate_sin = {-s1, s1};
    const DoubleLanes2* t = dense_.data();
    for (int m = 0; m < dense_orders_; ++m, t += 2) {
      k_sums += t[0] * cs;
      d_sums += t[1] * cs;
      cs = cs * rotate_cos + __builtin_shufflevector(cs, cs, 1, 0) * rotate_sin;
    }
    *k = k_sums[0] + k_sums[1];
    *d = d_sums[0] + d_sums[1];
  }
  /// Whether evaluateLanes applies: coefficients that do not depend on the frequency and an even
  /// basis step (the double-angle recurrence above).
  bool lanesApply() const { return !frequency_dependent_ && basis_.step() % 2 == 0; }
  /// The double-angle evaluate() for four samples, one per lane, where lanesApply(): every lane
  /// goes through the same operations as one sample does, so it gets the same bits.
  void evaluateLanes(DoubleLanes4 c2, DoubleLanes4 s2, DoubleLanes4* k, DoubleLanes4* d) const {
    DoubleLanes4 c1, s1;
    firstOrder(c2, s2, &c1, &s1);
    // The cos and sin sums apart and added at the end, and the recurrence's -s1 as a product, as
    // the lanes of evaluate() compute them.
    DoubleLanes4 k_cos = splat<DoubleLanes4>(k_coefficients_[0]), k_sin = splat<DoubleLanes4>(0.0);
    DoubleLanes4 d_cos = splat<DoubleLanes4>(d_coefficients_[0]), d_sin = splat<DoubleLanes4>(0.0);
    DoubleLanes4 c = c1, s = s1;
    const DoubleLanes4 minus_s1 = -s1;
    const DoubleLanes2* t = dense_.data();
    for (int m = 0; m < dense_orders_; ++m, t += 2) {
      k_cos += t[0][0] * c;
      k_sin += t[0][1] * s;
      d_cos += t[1][0] * c;
      d_sin += t[1][1] * s;
      const DoubleLanes4 next = c * c1 + s * minus_s1;
      s = s * c1 + c * s1;
      c = next;
    }
    *k = k_cos + k_sin;
    *d = d_cos + d_sin;
  }

 private:
  /// cos and sin of the basis's first order from the double angle (c2, s2): (c2, s2)^(step / 2) as a
  /// complex power, for one sample (V = double) or lanes of them, with the same operations.
  template <class V>
  void firstOrder(V c2, V s2, V* c1, V* s1) const {
    V c = c2, s = s2;
    for (int p = 2; p <= basis_.step() / 2; ++p) {
      const V next = c * c2 - s * s2;
      s = s * c2 + c * s2;
      c = next;
    }
    *c1 = c;
    *s1 = s;
  }
  /// Re-interpolates the coefficients when the frequency differs from the last one.
  void followFrequency(double frequency) {
    const bool same = frequency == cached_frequency_ || (std::isnan(frequency) && cached_is_nan_);
    if (!same) refresh(frequency);
  }
  void refresh(double frequency);
  /// HarmonicModel::evaluate with the orders already converted to basis indices (no integer division
  /// per term), the same operations in the same order, so the same bits.
  double sum(const double* coefficients, const std::vector<int>& indices) const {
    double m = coefficients[0];
    const std::size_t n = indices.size();
    for (std::size_t i = 0; i < n; ++i) {
      m += coefficients[1 + i] * basis_.cosAt(indices[i]) + coefficients[1 + n + i] * basis_.sinAt(indices[i]);
    }
    return m;
  }

  const HarmonicModel* k_;
  const HarmonicModel* d_;
  HarmonicBasis basis_;
  std::vector<double> k_coefficients_, d_coefficients_;
  std::vector<int> k_indices_, d_indices_;  // basis index of each order
  // For basis index m = 1, 2, ...: K's (cos, sin) coefficients, then D's (zero for an absent order).
  std::vector<DoubleLanes2> dense_;
  int dense_orders_ = 0;
  bool frequency_dependent_;
  double cached_frequency_ = 0.0;
  bool cached_is_nan_ = false;
};

}  // namespace core
}  // namespace hrg_gyro
