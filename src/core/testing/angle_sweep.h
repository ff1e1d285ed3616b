// Test support: measure the wave-angle map theta -> theta~ of a pickoff (noise free, signal level)
// over a sweep of true angles and decompose the error theta~ - theta into harmonics of theta.
#pragma once

#include <cmath>
#include <vector>

#include "hrg_gyro/core/common/units.h"
#include "hrg_gyro/core/model/correction_matrix.h"
#include "hrg_gyro/core/signal/wave_estimator.h"
#include "hrg_gyro/core/simulation/signal_synthesizer.h"

namespace hrg_gyro {
namespace core {
namespace testing {

/// Coefficients of theta~ - theta = c0 + sum_k c[k] cos k theta + s[k] sin k theta, k = 1 .. max.
struct AngleErrorHarmonics {
  double c0 = 0.0;
  std::vector<double> c, s;
};

/// Sweeps `points` true angles evenly over [0, pi) (one period of every even harmonic).
inline AngleErrorHarmonics sweepAngleError(const PickoffDefects& defects, WaveParameters wave,
                                           const CorrectionMatrix& correction = {}, int points = 256,
                                           int samples_per_period = 32, int max_order = 16) {
  SignalSynthesizer synth(defects, samples_per_period, 1);
  std::vector<double> theta(points), err(points);
  for (int i = 0; i < points; ++i) {
    theta[i] = kPi * i / points;
    wave.theta = theta[i];
    const ChannelVector z = correction.apply(synth.period(wave, wave.theta));
    WaveState w;
    estimateWave(z, WaveLimits{}, &w);
    err[i] = wrapToPi(2.0 * (w.theta - theta[i])) / 2.0;  // theta is defined modulo pi
  }
  AngleErrorHarmonics h;
  h.c.assign(max_order + 1, 0.0);
  h.s.assign(max_order + 1, 0.0);
  for (int i = 0; i < points; ++i) h.c0 += err[i] / points;
  // Even orders are orthogonal on the grid over [0, pi); odd orders are not resolved there.
  for (int k = 2; k <= max_order; k += 2) {
    for (int i = 0; i < points; ++i) {
      h.c[k] += 2.0 / points * err[i] * std::cos(k * theta[i]);
      h.s[k] += 2.0 / points * err[i] * std::sin(k * theta[i]);
    }
  }
  return h;
}

}  // namespace testing
}  // namespace core
}  // namespace hrg_gyro
