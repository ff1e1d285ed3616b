#include "hrg_gyro/core/alignment/base_motion_scan.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "hrg_gyro/core/simulation/gaussian_noise.h"

namespace hrg_gyro {
namespace core {
namespace {

constexpr double kRate = 200.0, kWhite = 8.75e-6;

// Three channels of integrated angle: a rate each, white angle noise, and `extra(c, t)` (a step, a sway).
IntegratedAngleFit fitted(double seconds, std::uint64_t seed, const std::function<double(int, double)>& extra) {
  GaussianNoise noise(seed);
  std::vector<AngleSeries> series(3);
  const double rates[3] = {3e-5, -4e-5, 5.7e-5};
  for (int c = 0; c < 3; ++c) {
    series[c].columns = {c};
    series[c].regressors.assign(1, {});
  }
  const long n = std::lround(seconds * kRate);
  for (long k = 0; k <= n; ++k) {
    const double t = k / kRate;
    for (int c = 0; c < 3; ++c) series[c].push(t, 0, rates[c] * t + extra(c, t) + kWhite * noise.next(), &t);
  }
  IntegratedAngleFit fit(3, std::move(series));
  EXPECT_TRUE(fit.solve(1e12).ok);
  return fit;
}

TEST(BaseMotionScanTest, AStepIsFoundWhereAndAsLargeAsItWas) {
  // 5 urad about x and 2 urad about z at 61.3 s of 120 s: the size within its standard error.
  const IntegratedAngleFit fit = fitted(120.0, 3, [](int c, double t) {
    return t < 61.3 ? 0.0 : (c == 0 ? 5e-6 : c == 2 ? 2e-6 : 0.0);
  });
  const BaseStep s = strongestStep(fit, 1.0);
  ASSERT_TRUE(s.found);
  EXPECT_NEAR(s.time, 61.3, 0.2);  // a 22-sigma step is placed within tens of samples
  // sigma of a step at mid-window: 4 s / sqrt(n) = 0.16 urad per channel.
  EXPECT_NEAR(s.size(0), 5e-6, 0.8e-6);
  EXPECT_NEAR(s.size(1), 0.0, 0.8e-6);
  EXPECT_NEAR(s.size(2), 2e-6, 0.8e-6);
  EXPECT_GT(s.chi_square, 300.0);  // (5 / 0.23)^2 + (2 / 0.23)^2 = 548 expected
}

TEST(BaseMotionScanTest, AStillBaseShowsNoStepBeyondTheThreshold) {
  // The largest chi-square (3 degrees of freedom) over every point of a still 120 s window, 30 seeds:
  // what the default step_threshold (40) must stay above.
  double largest = 0.0;
  for (int seed = 1; seed <= 30; ++seed) {
    const IntegratedAngleFit fit = fitted(120.0, seed, [](int, double) { return 0.0; });
    largest = std::max(largest, strongestStep(fit, 1.0).chi_square);
  }
  std::printf("[ measured ] still windows, 30 seeds: largest step chi-square %.1f (threshold 40)\n", largest);
  EXPECT_LT(largest, 40.0);
}

TEST(BaseMotionScanTest, ASlowSwayShowsInTheBlockMeansNotInEachPoint) {
  const IntegratedAngleFit still = fitted(120.0, 5, [](int, double) { return 0.0; });
  const IntegratedAngleFit sway =
      fitted(120.0, 5, [](int c, double t) { return c == 0 ? 2e-6 * std::sin(2.0 * 3.14159265 * t / 30.0) : 0.0; });
  const BlockScatter a = lowFrequencyScatter(still, 2.0), b = lowFrequencyScatter(sway, 2.0);
  EXPECT_NEAR(a.ratio, 1.0, 0.2);
  EXPECT_TRUE(a.still());
  EXPECT_EQ(a.blocks, 60);
  EXPECT_GT(b.ratio, 2.0);
  EXPECT_FALSE(b.still());
  // Per point the same sway is nearly invisible: 1.4e-6 rms against 8.75e-6 of noise.
  EXPECT_LT(sway.result().scatter[0], 1.05);
}

TEST(BaseMotionScanTest, TheBlockLimitIsTheChiSquareQuantileOfTheBlocks) {
  // Against the exact quantiles (the regularised incomplete gamma inverted): chi-square 10 at 5 % is
  // 18.307, 30 at 1e-4 is 67.633, 100 at 1e-4 is 161.32.
  EXPECT_NEAR(chiSquareQuantile(10, 0.05), 18.307, 0.01 * 18.307);
  EXPECT_NEAR(chiSquareQuantile(30, 1e-4), 67.633, 0.005 * 67.633);
  EXPECT_NEAR(chiSquareQuantile(100, 1e-4), 161.32, 0.005 * 161.32);
  // Still 30 s windows: the share refused over 400 seeds stays near what the limit promises (1e-4 each
  // channel): none here.
  int refused = 0;
  for (int seed = 1; seed <= 400; ++seed) {
    refused += !lowFrequencyScatter(fitted(30.0, 1000 + seed, [](int, double) { return 0.0; }), 2.0).still();
  }
  EXPECT_LE(refused, 1);
}

TEST(BaseMotionScanTest, ChannelsThatDoNotSharePointsAreNotScanned) {
  std::vector<AngleSeries> series(2);
  for (int c = 0; c < 2; ++c) {
    series[c].columns = {c};
    series[c].regressors.assign(1, {});
    for (int k = 0; k < 100 + c; ++k) {
      const double t = k * 0.01;
      series[c].push(t, 0, 1e-5 * t + 1e-9 * ((k * 7919) % 13), &t);
    }
  }
  IntegratedAngleFit fit(2, std::move(series));
  ASSERT_TRUE(fit.solve(1e12).ok);
  EXPECT_FALSE(strongestStep(fit, 0.1).found);
}

}  // namespace
}  // namespace core
}  // namespace hrg_gyro
