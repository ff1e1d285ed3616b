#include "hrg_gyro/core/model/model_pair_evaluator.h"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace hrg_gyro {
namespace core {
namespace {

HarmonicBasis basisFor(const HarmonicModel& k, const HarmonicModel& d) {
  const int step = std::gcd(k.orderStep(), d.orderStep());
  return step == 0 ? HarmonicBasis(1, 0) : HarmonicBasis(step, std::max(k.maxOrder(), d.maxOrder()));
}

std::vector<int> basisIndices(const HarmonicModel& model, const HarmonicBasis& basis) {
  std::vector<int> indices;
  for (int order : model.orders()) indices.push_back(order / basis.step());
  return indices;
}

}  // namespace

ModelPairEvaluator::ModelPairEvaluator(const HarmonicModel& k, const HarmonicModel& d)
    : k_(&k),
      d_(&d),
      basis_(basisFor(k, d)),
      k_coefficients_(k.termCount()),
      d_coefficients_(d.termCount()),
      k_indices_(basisIndices(k, basis_)),
      d_indices_(basisIndices(d, basis_)),
      frequency_dependent_(k.frequencyDependent() || d.frequencyDependent()) {
  refresh(NAN);
}

void ModelPairEvaluator::refresh(double frequency) {
  k_->coefficientsAt(frequency, k_coefficients_.data());
  d_->coefficientsAt(frequency, d_coefficients_.data());
  const int basis_orders = basis_.step() == 0 ? 0 : basis_.maxOrder() / basis_.step();
  dense_.assign(2 * static_cast<std::size_t>(basis_orders), DoubleLanes2{0.0, 0.0});
  dense_orders_ = basis_orders;
  const auto spread = [&](const std::vector<double>& coefficients, const std::vector<int>& indices, int model) {
    const std::size_t n = indices.size();
    for (std::size_t i = 0; i < n; ++i) {
      if (indices[i] < 1) continue;  // order 0 lives in the mean
      DoubleLanes2& slot = dense_[2 * static_cast<std::size_t>(indices[i] - 1) + model];
      slot[0] += coefficients[1 + i];
      slot[1] += coefficients[1 + n + i];
    }
  };
  spread(k_coefficients_, k_indices_, 0);
  spread(d_coefficients_, d_indices_, 1);
  cached_frequency_ = frequency;
  cached_is_nan_ = std::isnan(frequency);
}

}  // namespace core
}  // namespace hrg_gyro
