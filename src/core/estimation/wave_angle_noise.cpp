#include "hrg_gyro/core/estimation/wave_angle_noise.h"

#include <algorithm>
#include <cmath>

namespace hrg_gyro {
namespace core {

void WaveAngleNoise::add(double t, double theta) {
  // The deviation of the previous sample from the line through its neighbours.
  if (history_ >= 2) {
    const double span = t - t_[0];
    if (span > 0.0) {
      const double a = (t - t_[1]) / span, b = 1.0 - a;
      const double deviation = theta_[1] - (a * theta_[0] + b * theta);
      sum_ += deviation * deviation / (1.0 + a * a + b * b);
      ++count_;
    }
  }
  theta_[0] = theta_[1];
  t_[0] = t_[1];
  theta_[1] = theta;
  t_[1] = t;
  history_ = std::min(history_ + 1, 2);
}

double WaveAngleNoise::perSample() const { return count_ > 0 ? std::sqrt(sum_ / count_) : 0.0; }

double WaveAngleNoise::attenuation(int order, double noise) { return std::exp(-0.5 * order * order * noise * noise); }

double WaveAngleNoise::correctionUncertainty(double coefficient, double attenuation) {
  return 0.1 * std::abs(coefficient) * (1.0 - attenuation);
}

}  // namespace core
}  // namespace hrg_gyro
