// The rate variance the processor reports: the configured value when there is one, the initial
// one until the estimate has settled, then 2 s^2 / dt^2 for white angle noise of variance s^2
// whatever the rate, floored, and a gap (or an output flagged PRECESSING) breaks the run of alphas
// without losing the estimate.
#include "hrg_gyro/core/processing/rate_noise_estimator.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "core/testing/refusal.h"
#include "hrg_gyro/core/common/yaml_field.h"
#include "hrg_gyro/core/processing/gyro_processor.h"

namespace hrg_gyro {
namespace core {
namespace {

// `n` outputs of a gyro turning at `rate` with white angle noise `sigma` on alpha, dt apart.
void feed(RateNoiseEstimator* e, int n, double rate, double sigma, double dt, std::uint64_t seed = 3) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> noise(0.0, sigma);
  for (int i = 0; i < n; ++i) e->add(rate * dt * i + (sigma > 0.0 ? noise(rng) : 0.0), dt, 0);
}

TEST(RateNoiseEstimatorTest, MeasuresWhiteAngleNoiseWhateverTheRate) {
  const double sigma = 2e-6, dt = 0.005;
  RateNoiseEstimator e;
  feed(&e, 20000, 0.3, sigma, dt);
  const double expected = 2.0 * sigma * sigma / (dt * dt);
  EXPECT_NEAR(e.variance(), expected, 0.15 * expected);
}

TEST(RateNoiseEstimatorTest, ReportsTheInitialVarianceUntilSettled) {
  RateNoiseSettings s;
  s.initial_variance = 3e-3;
  RateNoiseEstimator e(s);
  EXPECT_EQ(e.variance(), 3e-3);
  feed(&e, static_cast<int>(RateNoiseEstimator::kSettledDifferences) + 1, 0.1, 1e-6, 0.001);
  EXPECT_EQ(e.secondDifferences(), RateNoiseEstimator::kSettledDifferences - 1);
  EXPECT_EQ(e.variance(), 3e-3);
  e.add(0.1 * 0.001 * 201, 0.001, 0);
  EXPECT_NE(e.variance(), 3e-3);
}

TEST(RateNoiseEstimatorTest, ANoiselessGyroStillHasTheFloor) {
  RateNoiseEstimator e;
  feed(&e, 1000, 0.2, 0.0, 0.001);
  EXPECT_GE(e.variance(), RateNoiseEstimator::kMinimumVariance);
  EXPECT_LT(e.variance(), 1e-6);
}

TEST(RateNoiseEstimatorTest, AConfiguredVarianceIsReportedAsGiven) {
  RateNoiseSettings s;
  s.configured_variance = 2.5e-7;
  RateNoiseEstimator e(s);
  feed(&e, 1000, 0.2, 1e-3, 0.001);
  EXPECT_EQ(e.variance(), 2.5e-7);
}

TEST(RateNoiseEstimatorTest, AGapStartsANewRunOfAlphas) {
  RateNoiseEstimator e;
  feed(&e, 10, 0.0, 0.0, 0.001);
  const std::uint64_t before = e.secondDifferences();
  e.add(5.0, 0.001, kFlagGap);  // the re-anchored angle: no second difference across it
  e.add(5.0, 0.001, 0);
  e.add(5.0, 0.001, 0);
  EXPECT_EQ(e.secondDifferences(), before);
  e.add(5.0, 0.001, 0);
  EXPECT_EQ(e.secondDifferences(), before + 1);
  e.add(0.0, 0.001, kFlagReset);
  EXPECT_EQ(e.secondDifferences(), before + 1);
}

TEST(RateNoiseEstimatorTest, PrecessedOutputsAreNoNoiseOfTheGyro) {
  // The wave turned on command at 0.36 rad/s of apparent body rate from the 300th to the 600th
  // output: the two steps of alpha's slope would raise the estimate several times over (the second
  // run, without the flag).
  const double sigma = 2e-6, dt = 0.005;
  auto run = [&](bool flagged) {
    RateNoiseEstimator e;
    std::mt19937_64 rng(5);
    std::normal_distribution<double> noise(0.0, sigma);
    double alpha = 0.0;
    for (int i = 0; i < 3000; ++i) {
      const bool precessing = i >= 300 && i < 600;
      if (precessing) alpha += 0.36 * dt;
      e.add(alpha + noise(rng), dt, precessing && flagged ? kFlagPrecessing : 0);
    }
    return e.variance();
  };
  const double expected = 2.0 * sigma * sigma / (dt * dt);
  EXPECT_NEAR(run(true), expected, 0.15 * expected);
  EXPECT_GT(run(false), 3.0 * expected);
}

TEST(RateNoiseEstimatorTest, RefusesAPerfectGyroAndNamesTheParameter) {
  RateNoiseSettings s;
  s.configured_variance = 0.0;
  EXPECT_EQ(refusedKey([&] { RateNoiseEstimator e(s); }), "angular_velocity_variance");
  s.configured_variance = -1.0;
  s.initial_variance = NAN;
  EXPECT_EQ(refusedKey([&] { RateNoiseEstimator e(s); }), "initial_angular_velocity_variance");
}

}  // namespace
}  // namespace core
}  // namespace hrg_gyro
