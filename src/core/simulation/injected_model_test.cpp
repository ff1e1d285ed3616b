// The exact injected model at strong pickoff nonlinearity: the harmonic fit of K_eff must
// reproduce the pointwise effective scale factor (measured through the pickoffs noise free) to far
// below a ppm, so that it stays the reference of the calibration tests up to A/d0 = 0.2.
#include "hrg_gyro/core/simulation/injected_model.h"

#include <gtest/gtest.h>

#include <cstdio>

#include "hrg_gyro/core/estimation/harmonic_fit.h"
#include "hrg_gyro/core/signal/wave_estimator.h"
#include "hrg_gyro/core/simulation/intrinsic_model.h"
#include "hrg_gyro/core/simulation/signal_synthesizer.h"

namespace hrg_gyro {
namespace core {
namespace {

/// The measured angle of a noise-free wave at true angle theta.
double measuredAngle(const SimulationConfig& c, SignalSynthesizer& synth, double theta) {
  const ResonatorConfig& rc = c.resonator;
  WaveState w;
  estimateWave(synth.period({rc.amplitude, rc.quadrature, theta, rc.phase}, theta), WaveLimits{}, &w);
  return theta + wrapToPi(2.0 * (w.theta - theta)) / 2.0;
}

/// Largest difference, in ppm of |K0|, between the fitted K_eff and the pointwise g'(theta) K(theta)
/// at the measured angle, over theta between the fit's grid points.
double worstFitError(double amplitude_to_gap, const std::vector<int>& orders, double* cos4, double* cos8) {
  SimulationConfig c;
  c.resonator.scale_factor = HarmonicModel({2, 4}, -0.56, {-2e-4, 1e-4}, {1.5e-4, 0.0});
  c.pickoff.misplacement = {0.8e-3, -0.5e-3, 1.1e-3, 0.3e-3, -0.9e-3, 0.6e-3, 0.4e-3, -1.2e-3};
  c.pickoff.gain_error = {2.1e-3, -1.4e-3, 0.6e-3, 1.8e-3, -2.2e-3, 0.9e-3, 1.5e-3, -0.7e-3};
  c.pickoff.gap = c.resonator.amplitude / amplitude_to_gap;
  const EffectiveModel e = computeEffectiveModel(c, CorrectionMatrix(), orders, {2});
  const HarmonicModel k = toModel(e.scale_factor);
  const double k0 = std::abs(k.meanAt(NAN));
  *cos4 = e.scale_factor.cos[1] / k0;
  *cos8 = e.scale_factor.cos[3] / k0;
  PickoffDefects noiseless = c.pickoff;
  SignalSynthesizer synth(noiseless, c.resonator.samples_per_period, 1);
  double worst = 0.0;
  const double h = 1e-5;
  for (int i = 0; i < 997; ++i) {
    const double theta = kPi * (i + 0.37) / 997;
    const double slope = (measuredAngle(c, synth, theta + h) - measuredAngle(c, synth, theta - h)) / (2.0 * h);
    const double pointwise = c.resonator.scale_factor(theta, NAN) * slope;
    worst = std::max(worst, std::abs(k(measuredAngle(c, synth, theta), NAN) - pointwise));
  }
  return 1e6 * worst / k0;
}

TEST(InjectedModelTest, ExactUpToAmplitudeToGapOfOneFifth) {
  std::vector<int> orders;
  for (int n = 2; n <= 16; n += 2) orders.push_back(n);
  for (const double ratio : {0.05, 0.2}) {
    double cos4, cos8;
    const double worst = worstFitError(ratio, orders, &cos4, &cos8);
    std::printf(
        "[ measured ] A/d0 = %.2f: K_eff cos 4theta %.4g, cos 8theta %.4g of K0; fit up to order 16 "
        "reproduces the pointwise K_eff within %.3g ppm\n",
        ratio, cos4, cos8, worst);
    EXPECT_LT(worst, 0.01) << ratio;
  }
}

// The averaged resonator: through ideal pickoffs the injected D and G_v are the intrinsic (settled)
// ones, harmonic by harmonic; without a precession loop there is no G_v to fit.
TEST(InjectedModelTest, AveragedResonatorIsItsIntrinsicModelThroughIdealPickoffs) {
  SimulationConfig c;
  c.dynamics.model = DynamicsModel::kAveraged;
  c.dynamics.shell.damping_anisotropy = 4e-5;
  c.dynamics.shell.damping_axis = 0.4;
  c.dynamics.shell.frequency_split = 2.0 * kPi * 5e-3;
  c.dynamics.shell.frequency_axis = -0.7;
  c.dynamics.drive.gain_error_c = 2e-3;
  c.dynamics.drive.gain_error_s = -1e-3;
  c.dynamics.drive.phase_error = 1e-3;
  c.dynamics.drive.virtual_rate_gain_error = 3e-3;
  c.resonator.quadrature = 0.0;
  c.resonator.drift = HarmonicModel(1e-5);
  const IntrinsicModel intrinsic(c);
  const EffectiveModel e = computeEffectiveModel(c, CorrectionMatrix(), {2, 4}, {2, 4}, {2, 4});
  ASSERT_TRUE(e.virtual_rate_gain.ok);
  double worst_d = 0.0, worst_g = 0.0;
  for (int i = 0; i < 360; ++i) {
    const double theta = kPi * i / 360;
    worst_d = std::max(worst_d, std::abs(toModel(e.drift)(theta, NAN) - intrinsic.drift(theta)));
    worst_g = std::max(worst_g, std::abs(toModel(e.virtual_rate_gain)(theta, NAN) - intrinsic.virtualRateGain(theta)));
  }
  std::printf(
      "[ measured ] G_v mean %.8f, cos 2theta %.3g; largest difference from the intrinsic model: D %.2g rad/s, "
      "G_v %.2g\n",
      e.virtual_rate_gain.mean, e.virtual_rate_gain.cos[0], worst_d, worst_g);
  EXPECT_NEAR(e.drift.mean, intrinsic.meanDrift(), 1e-15);
  EXPECT_LT(worst_d, 2e-11);  // orders 6 and up: products of three small numbers (8e-12 rad/s)
  EXPECT_LT(worst_g, 1e-8);
  // G_v = 1 + e_v + g - gamma cos 2theta to first order.
  EXPECT_NEAR(e.virtual_rate_gain.mean, 1.0 + 3e-3 + 0.5e-3, 1e-5);
  EXPECT_NEAR(e.virtual_rate_gain.cos[0], -1.5e-3, 1e-5);

  c.dynamics.model = DynamicsModel::kHarmonic;
  EXPECT_FALSE(computeEffectiveModel(c, CorrectionMatrix(), {2}, {2}, {2, 4}).virtual_rate_gain.ok);
}

}  // namespace
}  // namespace core
}  // namespace hrg_gyro
