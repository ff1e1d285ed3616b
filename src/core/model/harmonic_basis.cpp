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
  fillFrom(std::cos(step_ * theta), std::sin(step_ * theta));
}

}  // namespace core
}  // namespace hrg_gyro
