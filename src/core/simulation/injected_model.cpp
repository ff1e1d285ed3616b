#include "hrg_gyro/core/simulation/injected_model.h"

#include <algorithm>
#include <cmath>

#include "hrg_gyro/core/common/units.h"
#include "hrg_gyro/core/estimation/harmonic_fit.h"
#include "hrg_gyro/core/signal/wave_estimator.h"
#include "hrg_gyro/core/simulation/intrinsic_model.h"
#include "hrg_gyro/core/simulation/signal_synthesizer.h"

namespace hrg_gyro {
namespace core {

double injectedBiasTrend(const SimulationConfig& config, double t) {
  const ResonatorConfig& rc = config.resonator;
  double d0 = config.dynamics.averaged() ? IntrinsicModel(config).meanDrift() : rc.drift.meanAt(rc.frequency);
  if (config.thermal.enabled) {
    d0 = atTemperature(config, config.thermal.profile.evaluate(t)).resonator.drift.meanAt(rc.frequency);
  }
  return d0 + rc.bias_drift.trendAt(t);
}

EffectiveModel computeEffectiveModel(const SimulationConfig& config, const CorrectionMatrix& correction,
                                     const std::vector<int>& k_orders, const std::vector<int>& d_orders,
                                     const std::vector<int>& gain_orders) {
  PickoffDefects noiseless = config.pickoff;
  noiseless.noise = 0.0;
  SignalSynthesizer synth(noiseless, config.resonator.samples_per_period, 1);
  const ResonatorConfig& rc = config.resonator;
  const int m = 4096;
  const double h = kPi / m;
  // g(theta) on the grid, two extra points at each end for the five-point central differences (the
  // three-point ones leave ~0.1 ppm of K0 at A/d0 = 0.2, where g' carries percent-level 4theta terms).
  std::vector<double> measured(m + 4);
  for (int j = -2; j <= m + 1; ++j) {
    const double theta = j * h;
    WaveState w;
    estimateWave(correction.apply(synth.period({rc.amplitude, rc.quadrature, theta, rc.phase}, theta)), WaveLimits{},
                 &w);
    measured[j + 2] = theta + wrapToPi(2.0 * (w.theta - theta)) / 2.0;
  }
  const IntrinsicModel intrinsic(config);
  const bool gain = intrinsic.averaged() && !gain_orders.empty();
  std::vector<FitPoint> kp, dp, gp;
  for (int j = 0; j < m; ++j) {
    const double theta = j * h;
    const double slope = (8.0 * (measured[j + 3] - measured[j + 1]) - (measured[j + 4] - measured[j])) / (12.0 * h);
    const double at = measured[j + 2];
    FitPoint k_point, d_point;
    k_point.theta = d_point.theta = at;
    k_point.value = intrinsic.scaleFactor(theta) * slope;
    d_point.value = intrinsic.drift(theta) * slope;
    kp.push_back(k_point);
    dp.push_back(d_point);
    if (gain) {
      FitPoint g_point;
      g_point.theta = at;
      g_point.value = intrinsic.virtualRateGain(theta) * slope;
      gp.push_back(g_point);
    }
  }
  std::vector<int> all;
  for (int k = 2; k <= 16; k += 2) all.push_back(k);
  const HarmonicFitResult k_all = fitHarmonics(kp, all, {}, INFINITY);
  const HarmonicFitResult d_all = fitHarmonics(dp, all, {}, INFINITY);
  EffectiveModel e;
  // The reference is exact: the harmonics carry no standard errors.
  e.scale_factor = selectOrders(k_all, k_orders);
  e.drift = selectOrders(d_all, d_orders);
  if (gain) e.virtual_rate_gain = selectOrders(fitHarmonics(gp, all, {}, INFINITY), gain_orders);
  for (HarmonicFitResult* f : {&e.scale_factor, &e.drift, &e.virtual_rate_gain}) {
    std::fill(f->cos_std.begin(), f->cos_std.end(), 0.0);
    std::fill(f->sin_std.begin(), f->sin_std.end(), 0.0);
  }
  e.nonlinearity_ppm = 1e6 * toModel(k_all).peakDeviation() / std::abs(k_all.mean);
  return e;
}

}  // namespace core
}  // namespace hrg_gyro
