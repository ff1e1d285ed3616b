// cos(k theta) and sin(k theta) for every harmonic order a model needs, from one sincos.
//
// Orders are multiples of a base step g (2 for the even harmonics of K and D); sincos(g theta) is
// computed once and the higher orders follow by the angle-addition recurrence, so the cost per sample
// is one sincos plus two multiply-adds per order instead of one sincos per order.
#pragma once

#include <vector>

namespace hrg_gyro {
namespace core {

class HarmonicBasis {
 public:
  HarmonicBasis() : HarmonicBasis(1, 0) {}
  /// Orders step, 2 step, ... up to max_order (max_order 0: the constant term only).
  HarmonicBasis(int step, int max_order);

  void evaluate(double theta);

  int step() const { return step_; }
  int maxOrder() const { return max_order_; }
  /// k must be a multiple of step() in [0, maxOrder()].
  double cosOf(int k) const { return cos_[k / step_]; }
  double sinOf(int k) const { return sin_[k / step_]; }
  /// By index m (order m step()): for callers that have converted their orders once.
  double cosAt(int m) const { return cos_[m]; }
  double sinAt(int m) const { return sin_[m]; }

 private:
  int step_;
  int max_order_;
  std::vector<double> cos_, sin_;  // index m holds order m * step_
};

}  // namespace core
}  // namespace hrg_gyro
