// cos(k theta) and sin(k theta) for every harmonic order a model needs, from one sincos.
//
// Orders are multiples of a base step g (2 for the even harmonics of K and D); sincos(g theta) is
// computed once and the higher orders follow by the angle-addition recurrence, so the cost per sample
// is one sincos plus two multiply-adds per order instead of one sincos per order.
#pragma once

#include <cstddef>
#include <vector>

namespace hrg_gyro {
namespace core {

class HarmonicBasis {
 public:
  HarmonicBasis() : HarmonicBasis(1, 0) {}
  /// Orders step, 2 step, ... up to max_order (max_order 0: the constant term only).
  HarmonicBasis(int step, int max_order);

  void evaluate(double theta);
  /// The same from c2 = cos 2 theta, s2 = sin 2 theta (exact; no trigonometry) when every order is
  /// even; otherwise falls back to evaluate(theta). Inline: the processor calls it for every sample.
  void evaluate(double theta, double c2, double s2) {
    const std::size_t n = cos_.size();
    if (n < 2) return;
    if (step_ % 2 != 0) {
      evaluate(theta);
      return;
    }
    // (c1, s1) = (c2, s2)^(step / 2) as a complex power.
    double c1 = c2, s1 = s2;
    for (int p = 2; p <= step_ / 2; ++p) {
      const double c = c1 * c2 - s1 * s2;
      s1 = s1 * c2 + c1 * s2;
      c1 = c;
    }
    fillFrom(c1, s1);
  }

  int step() const { return step_; }
  int maxOrder() const { return max_order_; }
  /// k must be a multiple of step() in [0, maxOrder()].
  double cosOf(int k) const { return cos_[k / step_]; }
  double sinOf(int k) const { return sin_[k / step_]; }
  /// By index m (order m step()): for callers that have converted their orders once.
  double cosAt(int m) const { return cos_[m]; }
  double sinAt(int m) const { return sin_[m]; }

 private:
  /// Orders 2 step, 3 step, ... by the angle-addition recurrence from (cos, sin) of the step.
  void fillFrom(double c1, double s1) {
    double* c = cos_.data();
    double* s = sin_.data();
    const std::size_t n = cos_.size();
    c[1] = c1;
    s[1] = s1;
    for (std::size_t m = 2; m < n; ++m) {
      c[m] = c[m - 1] * c1 - s[m - 1] * s1;
      s[m] = s[m - 1] * c1 + c[m - 1] * s1;
    }
  }

  int step_;
  int max_order_;
  std::vector<double> cos_, sin_;  // index m holds order m * step_
};

}  // namespace core
}  // namespace hrg_gyro
