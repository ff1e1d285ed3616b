// Theta-binned rates, the harmonic fit with its standard errors, and plateau detection.
#include <gtest/gtest.h>

#include "hrg_gyro/core/estimation/binned_rate_fit.h"
#include "hrg_gyro/core/estimation/harmonic_fit.h"
#include "hrg_gyro/core/estimation/plateau_detector.h"
#include "hrg_gyro/core/estimation/theta_binned_rates.h"
#include "hrg_gyro/core/simulation/gaussian_noise.h"

namespace hrg_gyro {
namespace core {
namespace {

TEST(HarmonicFit, RecoversCoefficientsOfAveragedPoints) {
  // Values are averages of M over spans of 0.3 rad: the fit must undo the sinc attenuation.
  const std::vector<int> orders{2, 4, 8};
  auto m = [](double th) { return 0.5 + 1e-3 * std::cos(2 * th) - 2e-3 * std::sin(4 * th) + 5e-4 * std::cos(8 * th); };
  std::vector<FitPoint> pts;
  const double span = 0.3;
  for (int i = 0; i < 60; ++i) {
    const double th = kPi * i / 60;
    double avg = 0.0;
    for (int j = 0; j < 2000; ++j) avg += m(th - span / 2 + span * (j + 0.5) / 2000) / 2000;
    pts.push_back({th, avg, 1.0, span, {}});
  }
  const HarmonicFitResult f = fitHarmonics(pts, orders);
  ASSERT_TRUE(f.ok) << f.reason;
  EXPECT_NEAR(f.mean, 0.5, 1e-9);
  EXPECT_NEAR(f.cos[0], 1e-3, 1e-9);
  EXPECT_NEAR(f.sin[1], -2e-3, 1e-9);
  EXPECT_NEAR(f.cos[2], 5e-4, 1e-9);
  EXPECT_LT(f.smallest_attenuation, 0.9);
}

TEST(HarmonicFit, StandardErrorsMatchTheScatterOfIndependentNoise) {
  GaussianNoise noise(3);
  const int trials = 400;
  double z2 = 0.0;
  for (int t = 0; t < trials; ++t) {
    std::vector<FitPoint> pts;
    for (int i = 0; i < 100; ++i) {
      const double th = kPi * i / 100;
      pts.push_back({th, 1.0 + 1e-3 * std::sin(2 * th) + 1e-4 * noise.next(), 1.0, 0.0, {}});
    }
    const HarmonicFitResult f = fitHarmonics(pts, {2, 4});
    z2 += std::pow((f.sin[0] - 1e-3) / f.sin_std[0], 2);
  }
  EXPECT_NEAR(z2 / trials, 1.0, 0.2);  // chi-square per degree of freedom
}

TEST(HarmonicFit, RefusesTooFewOrIllPlacedPoints) {
  std::vector<FitPoint> pts;
  for (int i = 0; i < 4; ++i) pts.push_back({0.1 * i, 1.0, 1.0, 0.0, {}});
  EXPECT_FALSE(fitHarmonics(pts, {2, 4}).ok);  // 4 points, 5 unknowns
  pts.clear();
  for (int i = 0; i < 40; ++i) pts.push_back({0.3 + 1e-4 * i, 1.0, 1.0, 0.0, {}});  // all at one angle
  const HarmonicFitResult f = fitHarmonics(pts, {2, 4});
  EXPECT_FALSE(f.ok);
  EXPECT_NE(f.reason.find("ill-conditioned"), std::string::npos);
}

TEST(ThetaBinnedRates, MeasuresTheRateAsAFunctionOfTheAngle) {
  // theta(t) with rate r(theta) = 0.03 (1 + 0.01 cos 2 theta): the binned fit returns r exactly.
  ThetaBinnedRates rates(64, 0.2, 8);
  double theta = 0.0;
  const double dt = 1e-3;
  for (int i = 0; i < 300000; ++i) {
    rates.add(toNanoseconds(1.0 + i * dt), theta, theta);
    auto r = [](double th) { return 0.03 * (1.0 + 0.01 * std::cos(2 * th)); };
    const double k1 = r(theta), k2 = r(theta + dt / 2 * k1), k3 = r(theta + dt / 2 * k2), k4 = r(theta + dt * k3);
    theta += dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
  }
  EXPECT_EQ(rates.coverage(0.05), 1.0);
  EXPECT_NEAR(rates.thetaSwept(), theta, 0.01);
  const HarmonicFitResult f = fitBinnedRates(rates, {2, 4}, 0.05);
  ASSERT_TRUE(f.ok) << f.reason;
  EXPECT_NEAR(f.mean, 0.03, 1e-9);
  EXPECT_NEAR(f.cos[0], 3e-4, 2e-9);
  EXPECT_NEAR(f.sin[0], 0.0, 2e-9);
  EXPECT_NEAR(f.cos[1], 0.0, 2e-9);
}

TEST(ThetaBinnedRates, EstimatesTheWhiteNoiseOfItsInput) {
  ThetaBinnedRates rates(32, 0.1, 2);
  GaussianNoise noise(1);
  for (int i = 0; i < 100000; ++i) {
    const double theta = 0.02 * i * 1e-3;
    rates.add(toNanoseconds(1.0 + i * 1e-3), theta, theta + 3e-5 * noise.next());
  }
  EXPECT_NEAR(rates.sampleNoise(), 3e-5, 1e-6);
  EXPECT_NEAR(rates.windowNoise(), 3e-5 / std::sqrt(101.0), 2e-7);
}

TEST(PlateauDetector, FindsSettledPlateausAndRestarts) {
  PlateauDetector d(PlateauSettings{2e-4, 2e-3, 1.0, 2e-4, 0.5});
  PlateauState s;
  for (int i = 0; i < 500; ++i) s = d.update(toNanoseconds(1.0 + i * 1e-2), 0.0);
  EXPECT_TRUE(s.settled);
  EXPECT_TRUE(s.is_static);
  const auto id = s.id;
  s = d.update(toNanoseconds(6.0), 0.05);  // a rate change starts a new plateau
  EXPECT_NE(s.id, id);
  EXPECT_FALSE(s.settled);
  for (int i = 1; i <= 150; ++i) s = d.update(toNanoseconds(6.0 + i * 1e-2), 0.05 + 1e-5 * ((i % 3) - 1));
  EXPECT_TRUE(s.settled);  // small noise does not break it
  EXPECT_FALSE(s.is_static);
  EXPECT_NEAR(s.rate, 0.05, 1e-5);
  const auto id2 = s.id;
  s = d.update(toNanoseconds(9.0), 0.05);  // a gap in the turntable stream
  EXPECT_NE(s.id, id2);
}

}  // namespace
}  // namespace core
}  // namespace hrg_gyro
