#include "hrg_gyro/core/model/harmonic_basis.h"

#include <cmath>
#include <stdexcept>

namespace hrg_gyro {
namespace core {

HarmonicBasis::HarmonicBasis(int step, int max_order) : step_(step), max_order_(max_order) {
  if (step < 1 || max_order < 0 || max_order % step != 0) {
    throw std::invalid_argument("harmonic basis: max order must be a non-negative multiple of the step");
  }
  cos_.assign(max_order / step + 1, 1.0);
  sin_.assign(max_order / step + 1, 0.0);
}

void HarmonicBasis::evaluate(double theta) {
  const std::size_t n = cos_.size();
  if (n < 2) return;
  const double c1 = std::cos(step_ * theta), s1 = std::sin(step_ * theta);
  cos_[1] = c1;
  sin_[1] = s1;
  for (std::size_t m = 2; m < n; ++m) {
    cos_[m] = cos_[m - 1] * c1 - sin_[m - 1] * s1;
    sin_[m] = sin_[m - 1] * c1 + cos_[m - 1] * s1;
  }
}

}  // namespace core
}  // namespace hrg_gyro
