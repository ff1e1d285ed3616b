#include "hrg_gyro/core/compensator.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>

namespace hrg_gyro {
namespace core {
namespace {

HarmonicBasis basisFor(const HarmonicModel& k, const HarmonicModel& d) {
  const int step = std::gcd(k.orderStep(), d.orderStep());
  const int max_order = std::max(k.maxOrder(), d.maxOrder());
  return step == 0 ? HarmonicBasis(1, 0) : HarmonicBasis(step, max_order);
}

}  // namespace

Compensator::Compensator(std::shared_ptr<const GyroParameters> parameters)
    : parameters_(std::move(parameters)),
      basis_(basisFor(parameters_->scale_factor, parameters_->drift)),
      k_coefficients_(parameters_->scale_factor.termCount()),
      d_coefficients_(parameters_->drift.termCount()),
      frequency_dependent_(parameters_->scale_factor.frequencyDependent() || parameters_->drift.frequencyDependent()),
      earth_rate_(parameters_->earth_rate.verticalRate()) {
  refreshCoefficients(NAN);
}

void Compensator::refreshCoefficients(double frequency) {
  parameters_->scale_factor.coefficientsAt(frequency, k_coefficients_.data());
  parameters_->drift.coefficientsAt(frequency, d_coefficients_.data());
  cached_frequency_ = frequency;
}

AngleIncrement Compensator::step(double theta_previous, double theta, double dt, double frequency_mid) {
  // The frequency moves slowly: re-interpolate the coefficients only when it changes.
  if (frequency_dependent_ && !(frequency_mid == cached_frequency_) &&
      !(std::isnan(frequency_mid) && std::isnan(cached_frequency_))) {
    refreshCoefficients(frequency_mid);
  }
  AngleIncrement inc;
  inc.dt = dt;
  inc.dtheta = theta - theta_previous;
  inc.theta_mid = 0.5 * (theta + theta_previous);
  inc.frequency = frequency_mid;
  basis_.evaluate(inc.theta_mid);
  inc.scale_factor = parameters_->scale_factor.evaluate(basis_, k_coefficients_.data());
  inc.drift = parameters_->drift.evaluate(basis_, d_coefficients_.data());
  inc.dalpha = (inc.dtheta - inc.drift * dt) / inc.scale_factor;
  inc.dalpha_earth_fixed = inc.dalpha - earth_rate_ * dt;
  return inc;
}

}  // namespace core
}  // namespace hrg_gyro
