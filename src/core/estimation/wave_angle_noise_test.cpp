// The wave angle's per-sample noise from the samples' deviations, and the attenuation it corrects.
#include "hrg_gyro/core/estimation/wave_angle_noise.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace hrg_gyro {
namespace core {
namespace {

TEST(WaveAngleNoiseTest, MeasuresWhiteNoiseOnACurvedNonUniformSweep) {
  std::mt19937_64 random(5);
  std::normal_distribution<double> normal(0.0, 1.0);
  WaveAngleNoise clean, noisy;
  double t = 0.0;
  for (int i = 0; i < 200000; ++i) {
    t += 1e-3 * (1.0 + 0.3 * std::sin(0.01 * i));  // jittered steps: the line weights move
    const double theta = 0.2 + 0.03 * t + 1e-9 * t * t;
    clean.add(t, theta);
    noisy.add(t, theta + 2e-4 * normal(random));
  }
  EXPECT_LT(clean.perSample(), 1e-9);
  EXPECT_NEAR(noisy.perSample(), 2e-4, 2e-4 * 0.01);
}

TEST(WaveAngleNoiseTest, SamplesAcrossAGapAreNotNeighbours) {
  // Two chains whose angles differ by a jump: without restart() the jump would count as noise.
  WaveAngleNoise noise;
  for (int i = 0; i < 100; ++i) noise.add(i * 1e-3, 0.01 * i);
  noise.restart();
  for (int i = 0; i < 100; ++i) noise.add(1.0 + i * 1e-3, 3.0 + 0.01 * i);
  EXPECT_LT(noise.perSample(), 1e-12);
  EXPECT_EQ(WaveAngleNoise().perSample(), 0.0);
}

TEST(WaveAngleNoiseTest, AttenuationIsTheMeanOfTheNoisyCosine) {
  // E[cos(k (theta + n))] = exp(-k^2 s^2 / 2) cos(k theta) for Gaussian n of deviation s
  // (here at theta = 0).
  std::mt19937_64 random(9);
  std::normal_distribution<double> normal(0.0, 0.2);
  double mean = 0.0;
  const int n = 400000;
  for (int i = 0; i < n; ++i) mean += std::cos(4.0 * normal(random)) / n;
  EXPECT_NEAR(mean, WaveAngleNoise::attenuation(4, 0.2), 3e-3);
  EXPECT_DOUBLE_EQ(WaveAngleNoise::attenuation(2, 0.0), 1.0);
  EXPECT_DOUBLE_EQ(WaveAngleNoise::correctionUncertainty(-0.5, 0.8), 0.1 * 0.5 * 0.2);
}

}  // namespace
}  // namespace core
}  // namespace hrg_gyro
