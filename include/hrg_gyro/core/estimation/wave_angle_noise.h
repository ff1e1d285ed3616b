// The white noise of the measured wave angle, per sample, and the correction it asks of the fit.
//
// Estimated from the samples themselves: each sample's deviation from the line through its two
// neighbours (a smooth sweep leaves none), scaled to one sample's variance. Noise of theta inside
// cos(k theta) attenuates the regressors by exp(-k^2 s^2 / 2) on average (s the per-sample noise); the
// increment regression (increment_model.h) undoes that factor on the fitted harmonics, and counts a
// tenth of the correction as its uncertainty.
#pragma once

#include <cstddef>

namespace hrg_gyro {
namespace core {

class WaveAngleNoise {
 public:
  /// A sample of a chain at t s; samples across a gap are not neighbours: restart() between chains.
  void add(double t, double theta);
  void restart() { history_ = 0; }
  /// rad per sample (0 before any sample had two neighbours).
  double perSample() const;

  /// The mean attenuation of order k's regressors by angle noise s rad.
  static double attenuation(int order, double noise);
  /// The uncertainty of a coefficient's correction: a tenth of it. The noise is estimated well
  /// (0.05 % at 0.2 rad), but noise correlated from sample to sample would make it off by more.
  static double correctionUncertainty(double coefficient, double attenuation);

 private:
  int history_ = 0;
  double theta_[2] = {0.0, 0.0}, t_[2] = {0.0, 0.0};
  double sum_ = 0.0;
  std::size_t count_ = 0;
};

}  // namespace core
}  // namespace hrg_gyro
