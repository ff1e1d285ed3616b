// The increment regression on noiseless sweeps: exact for any window and any non-uniform sweep, and
// its refusals.
#include "hrg_gyro/core/estimation/increment_regression.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "hrg_gyro/core/model/earth_rate.h"
#include "hrg_gyro/core/model/harmonic_model.h"

namespace hrg_gyro {
namespace core {
namespace {

// K with a 3 % cos 4theta and a 0.3 % cos 8theta term: theta sweeps far from uniformly.
const HarmonicModel kStrongK({2, 4, 8}, -0.56, {-6e-4, -0.56 * 0.03, 0.56 * 0.003}, {4e-4, 2e-4, 0.0});
const HarmonicModel kDrift({2}, 1e-5, {2e-5}, {-1e-5});

/// An axis leaning off the table's axis: its horizontal component in the platter frame, and the
/// horizontal Earth rate it senses (heading psi = -phi, a zero azimuth), fitted in `slot` (-1: not).
struct Lean {
  double x = 0.0, y = 0.0, horizontal_rate = 0.0;
  int slot = -1;
  double rate(double phi) const { return horizontal_rate * (x * std::cos(-phi) + y * std::sin(-phi)); }
};

/// Two plateaus (table rates w1 and w2), RK4 at 1 kHz; table angle logged exactly; white noise of
/// `noise` rad on the measured theta.
void sweep(IncrementRegression* r, double w1, double w2, double seconds, double window, double earth,
           const HarmonicModel& k_model = kStrongK, double noise = 0.0, const Lean& lean = Lean()) {
  double theta = 0.2, phi = 0.0, t = 0.0;
  std::mt19937_64 random(11);
  std::normal_distribution<double> normal(0.0, 1.0);
  const double h = 1e-3;
  int group = 0;
  for (double w : {w1, w2}) {
    r->startChain(group++, window);
    auto rate = [&](double th, double ph) { return k_model(th) * (w + earth + lean.rate(ph)) + kDrift(th); };
    for (long i = 0; i < static_cast<long>(seconds / h); ++i) {
      r->add(toNanoseconds(1.0 + t), theta + noise * normal(random), phi, NAN, lean.slot, -phi);
      const double k1 = rate(theta, phi), k2 = rate(theta + h / 2 * k1, phi + w * h / 2),
                   k3 = rate(theta + h / 2 * k2, phi + w * h / 2), k4 = rate(theta + h * k3, phi + w * h);
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

TEST(IncrementRegressionTest, FitsTheHorizontalEarthRateOfALeaningAxisInsteadOfD) {
  // An axis 3 mrad off the table's axis at latitude 0.9 rad: the horizontal Earth rate it senses
  // turns with the table and, unmodelled, lands in D's order 2 (theta moves with about 1.8 phi).
  const HarmonicModel k({2}, -0.56, {-6e-4}, {4e-4});
  Lean lean;
  lean.x = 3e-3;
  lean.y = -2e-3;
  lean.horizontal_rate = kEarthRotationRate * std::cos(0.9);
  IncrementRegression without({2}, {2}, 64);
  sweep(&without, 0.05, -0.05, 260.0, 2.0, 5e-5, k, 0.0, lean);
  lean.slot = 1;  // slot 0 unused: no columns for it
  IncrementRegression with({2}, {2}, 64, 0, 2);
  sweep(&with, 0.05, -0.05, 260.0, 2.0, 5e-5, k, 0.0, lean);
  const IncrementFit a = without.solve(5e-5, 0.0, 0.1, 1e8), b = with.solve(5e-5, 0.0, 0.1, 1e8);
  ASSERT_TRUE(a.ok) << a.reason;
  ASSERT_TRUE(b.ok) << b.reason;
  const double leak = std::hypot(a.d.cos[0] - 2e-5, a.d.sin[0] + 1e-5);
  const double left = std::hypot(b.d.cos[0] - 2e-5, b.d.sin[0] + 1e-5);
  ASSERT_EQ(b.horizontal.size(), 1u);
  const double expected_cos = -0.56 * lean.horizontal_rate * lean.x,
               expected_sin = -0.56 * lean.horizontal_rate * lean.y;
  std::printf(
      "D order 2 off by %.3g rad/s unmodelled, %.3g rad/s with the lean fitted; lean's rate %.4g %.4g rad/s "
      "(expected %.4g %.4g)\n",
      leak, left, b.horizontal[0].cos, b.horizontal[0].sin, expected_cos, expected_sin);
  EXPECT_GT(leak, 1e-9);
  EXPECT_LT(left, 2e-10);
  EXPECT_NEAR(b.d.mean, 1e-5, 2e-10);
  EXPECT_EQ(b.horizontal[0].slot, 1);
  EXPECT_NEAR(b.horizontal[0].cos, expected_cos, 1e-3 * std::abs(expected_cos));
  EXPECT_NEAR(b.horizontal[0].sin, expected_sin, 1e-3 * std::abs(expected_sin));
  without.startChain(0, 2.0);  // a slot it was not made with
  EXPECT_THROW(without.add(toNanoseconds(999.0), 0.0, 0.0, NAN, 0, 0.0), std::invalid_argument);
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
