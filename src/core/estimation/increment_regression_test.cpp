// The increment regression on noiseless sweeps: exact for any window and any non-uniform sweep, and
// its refusals.
#include "hrg_gyro/core/estimation/increment_regression.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "hrg_gyro/core/model/harmonic_model.h"

namespace hrg_gyro {
namespace core {
namespace {

// K with a 3 % cos 4theta and a 0.3 % cos 8theta term: theta sweeps far from uniformly.
const HarmonicModel kStrongK({2, 4, 8}, -0.56, {-6e-4, -0.56 * 0.03, 0.56 * 0.003}, {4e-4, 2e-4, 0.0});
const HarmonicModel kDrift({2}, 1e-5, {2e-5}, {-1e-5});

/// Two plateaus (table rates w1 and w2), RK4 at 1 kHz; table angle logged exactly; white noise of
/// `noise` rad on the measured theta.
void sweep(IncrementRegression* r, double w1, double w2, double seconds, double window, double earth,
           const HarmonicModel& k_model = kStrongK, double noise = 0.0) {
  double theta = 0.2, phi = 0.0, t = 0.0;
  std::mt19937_64 random(11);
  std::normal_distribution<double> normal(0.0, 1.0);
  const double h = 1e-3;
  int group = 0;
  for (double w : {w1, w2}) {
    r->startChain(group++, window);
    auto rate = [&](double th) { return k_model(th) * (w + earth) + kDrift(th); };
    for (long i = 0; i < static_cast<long>(seconds / h); ++i) {
      r->add(toNanoseconds(1.0 + t), theta + noise * normal(random), phi);
      const double k1 = rate(theta), k2 = rate(theta + h / 2 * k1), k3 = rate(theta + h / 2 * k2),
                   k4 = rate(theta + h * k3);
      theta += h / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
      phi += w * h;
      t += h;
    }
    r->endChain();
  }
}

TEST(IncrementRegressionTest, ExactForAnyWindowUnderStrongNonlinearity) {
  for (double window : {0.5, 2.0, 8.0}) {
    IncrementRegression r({2, 4, 8}, {2}, 64);
    sweep(&r, 0.05, -0.05, 130.0, window, 5e-5);
    const IncrementFit fit = r.solve(5e-5, 0.0, 0.1, 1e8);
    ASSERT_TRUE(fit.ok) << fit.reason;
    const double true_cos[] = {-6e-4, -0.56 * 0.03, 0.56 * 0.003}, true_sin[] = {4e-4, 2e-4, 0.0};
    double worst = std::abs(fit.k.mean + 0.56);
    for (std::size_t j = 0; j < 3; ++j) {
      worst = std::max(worst, std::abs(fit.k.cos[j] - true_cos[j]));
      worst = std::max(worst, std::abs(fit.k.sin[j] - true_sin[j]));
    }
    std::printf("window %.1f s: largest K coefficient error %.3g ppm of |K0|, mean window %.3f s\n", window,
                1e6 * worst / 0.56, fit.mean_window);
    EXPECT_LT(worst / 0.56, 2e-8) << "window " << window;
    EXPECT_NEAR(fit.d.mean, 1e-5, 1e-10);
    EXPECT_NEAR(fit.d.cos[0], 2e-5, 1e-10);
    if (window <= 2.0) {  // long windows leave bins empty
      EXPECT_GT(fit.binned.size(), 32u) << "window " << window;
    }
    EXPECT_LT(fit.k.residual_rms / 0.56, 1e-6);
  }
}

TEST(IncrementRegressionTest, CorrectsTheBasisForNoiseInTheta) {
  // Noise s in theta makes cos(k theta) average exp(-k^2 s^2 / 2) cos(k theta): at s = 0.2 rad that
  // is 27 % for order 4, far above the statistical error at this noise. (Realistic noise, 1e-4 rad,
  // attenuates by 1e-7; this shows the correction where it can be seen.)
  const double noise = 0.2, a4 = -0.056;
  const HarmonicModel k({4}, -0.56, {a4}, {0.0});
  IncrementRegression r({4}, {2}, 64);
  sweep(&r, 0.05, -0.05, 300.0, 2.0, 0.0, k, noise);
  const IncrementFit fit = r.solve(0.0, 0.0, 0.1, 1e8);
  ASSERT_TRUE(fit.ok) << fit.reason;
  const double attenuation = std::exp(-0.5 * 16 * noise * noise);
  const double uncorrected = fit.k.cos[0] / attenuation;
  std::printf("estimated angle noise %.4f rad; cos 4theta: true %.5f, corrected %.5f +- %.5f, uncorrected %.5f\n",
              fit.angle_noise, a4, fit.k.cos[0], fit.k.cos_std[0], uncorrected);
  EXPECT_NEAR(fit.angle_noise, noise, 0.01 * noise);
  EXPECT_LT(std::abs(fit.k.cos[0] - a4), 4.0 * fit.k.cos_std[0]);
  EXPECT_GT(std::abs(uncorrected - a4), 5.0 * fit.k.cos_std[0]);
}

TEST(IncrementRegressionTest, RefusesBadArgumentsAndTooLittleData) {
  EXPECT_THROW(IncrementRegression({0, 2}, {2}, 64), std::invalid_argument);
  EXPECT_THROW(IncrementRegression({2}, {2}, 0), std::invalid_argument);
  IncrementRegression r({2, 4}, {2}, 64);
  EXPECT_THROW(r.add(1, 0.0, 0.0), std::logic_error);
  EXPECT_THROW(r.startChain(0, 0.0), std::invalid_argument);
  r.startChain(0, 1.0);
  for (int i = 0; i < 3000; ++i) r.add(toNanoseconds(1.0 + i * 1e-3), 0.2 - 0.028 * i * 1e-3, 0.05 * i * 1e-3);
  const IncrementFit fit = r.solve(0.0, 0.0, 0.1, 1e8);
  EXPECT_FALSE(fit.ok);
  EXPECT_NE(fit.reason.find("window increments"), std::string::npos) << fit.reason;
}

}  // namespace
}  // namespace core
}  // namespace hrg_gyro
