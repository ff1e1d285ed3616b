#include "hrg_gyro/core/simulation/intrinsic_model.h"

#include <cmath>

#include "hrg_gyro/core/common/units.h"

namespace hrg_gyro {
namespace core {

IntrinsicModel::IntrinsicModel(const SimulationConfig& config)
    : frequency_(config.resonator.frequency),
      scale_factor_(config.resonator.scale_factor),
      added_drift_(config.resonator.drift) {
  const DynamicsConfig& d = config.dynamics;
  if (!d.averaged()) {
    mean_drift_ = added_drift_.meanAt(frequency_);
    return;
  }
  steady_.emplace(d.shell, d.loops, d.drive);
  first_order_ = firstOrderModel(d.shell, d.loops, d.drive);
  scale_factor_ = first_order_.scale_factor;
  k0_ = d.shell.scaleFactor();
  // The exact drift is smooth in theta (its harmonics fall off geometrically with the drive's small
  // errors): the mean over 256 angles is exact to rounding.
  const int n = 256;
  double sum = 0.0;
  for (int i = 0; i < n; ++i) sum += steady_->drift(kPi * i / n);
  mean_drift_ = sum / n + added_drift_.meanAt(frequency_);
}

double IntrinsicModel::scaleFactor(double theta) const { return scale_factor_(theta, frequency_); }

double IntrinsicModel::drift(double theta) const {
  if (!steady_) return added_drift_(theta, frequency_);
  return steady_->drift(theta) + added_drift_(theta, frequency_);
}

double IntrinsicModel::virtualRateGain(double theta) const {
  if (!steady_) return 0.0;
  // The settled gain, times the quadrature loop's lag as it scales K: 1 - L (1 + cos 4(theta - theta_w)).
  return steady_->virtualRateGain(theta) * first_order_.scale_factor(theta) / k0_;
}

}  // namespace core
}  // namespace hrg_gyro
