#include "hrg_gyro/core/processing/rate_noise_estimator.h"

#include <algorithm>
#include <cmath>

#include "hrg_gyro/core/common/yaml_field.h"
#include "hrg_gyro/core/processing/gyro_processor.h"

namespace hrg_gyro {
namespace core {

void RateNoiseSettings::validate() const {
  if (configured_variance == 0.0 || !std::isfinite(configured_variance)) {
    throw ConfigError("angular_velocity_variance",
                      "must be positive ((rad/s)^2), or negative for the measured noise; 0 would claim a perfect gyro");
  }
  if (!(initial_variance > 0.0) || !std::isfinite(initial_variance)) {
    throw ConfigError("initial_angular_velocity_variance", "must be positive ((rad/s)^2)");
  }
}

RateNoiseEstimator::RateNoiseEstimator(const RateNoiseSettings& settings) : settings_(settings) {
  settings_.validate();
}

void RateNoiseEstimator::add(double alpha, double dt, std::uint8_t flags) {
  // A precessed sample's alpha turns with the commanded rate: its steps are not the gyro's noise.
  if (flags & (kFlagGap | kFlagReset | kFlagPrecessing)) {
    history_ = 0;
    return;
  }
  if (history_ >= 2) {
    const double d2 = alpha - 2.0 * alpha1_ + alpha2_;
    ++second_differences_;
    d2_variance_ += (d2 * d2 - d2_variance_) * (second_differences_ < 1000 ? 1.0 / second_differences_ : 1e-3);
  }
  alpha2_ = alpha1_;
  alpha1_ = alpha;
  if (history_ < 2) ++history_;
  dt_last_ = dt;
}

double RateNoiseEstimator::variance() const {
  if (settings_.configured_variance > 0.0) return settings_.configured_variance;
  if (second_differences_ < kSettledDifferences || !(dt_last_ > 0.0)) return settings_.initial_variance;
  return std::max((d2_variance_ / 3.0) / (dt_last_ * dt_last_), kMinimumVariance);
}

}  // namespace core
}  // namespace hrg_gyro
