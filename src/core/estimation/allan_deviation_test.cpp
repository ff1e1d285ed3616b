// Overlapping Allan deviation: the textbook slopes and the readings taken from them.
#include "hrg_gyro/core/estimation/allan_deviation.h"

#include <gtest/gtest.h>

#include "hrg_gyro/core/simulation/gaussian_noise.h"

namespace hrg_gyro {
namespace core {
namespace {

TEST(AllanDeviationTest, WhiteAngleNoiseHasSlopeMinusOneAndGivesQ) {
  GaussianNoise g(1);
  const double q = 2e-5, tau0 = 0.005;
  std::vector<double> angle(400000);
  for (std::size_t k = 0; k < angle.size(); ++k) angle[k] = 0.01 * k * tau0 + q * g.next();  // + constant rate
  const AllanResult r = allanDeviation(angle, tau0);
  ASSERT_TRUE(r.angle_white_noise.identified);
  EXPECT_NEAR(r.angle_white_noise.value, q, 0.05 * q);
  EXPECT_FALSE(r.bias_instability.identified);
  // sigma(tau) = sqrt(3) Q / tau at every point
  for (const AllanPoint& p : r.curve) {
    if (p.tau < 10.0) {
      EXPECT_NEAR(p.deviation, std::sqrt(3.0) * q / p.tau, 4 * p.error + 0.02 * p.deviation) << p.tau;
    }
  }
}

TEST(AllanDeviationTest, RateWhiteNoiseGivesTheAngleRandomWalk) {
  GaussianNoise g(2);
  const double n = 1e-4, tau0 = 0.01;  // rad/sqrt(s)
  std::vector<double> angle(300000);
  double theta = 0.0;
  for (double& a : angle) {
    theta += n * std::sqrt(tau0) * g.next();
    a = theta;
  }
  const AllanResult r = allanDeviation(angle, tau0);
  ASSERT_TRUE(r.angle_random_walk.identified);
  EXPECT_NEAR(r.angle_random_walk.value, n, 0.05 * n);
  EXPECT_FALSE(r.angle_white_noise.identified);
}

TEST(AllanDeviationTest, FlickerLikeBiasGivesAFlatBottomAndB) {
  // 1/f noise approximated by Gauss-Markov processes with log-spaced correlation times.
  GaussianNoise g(3);
  const double tau0 = 0.05, b = 1e-6;
  std::vector<double> times{1.0, 3.0, 10.0, 30.0, 100.0, 300.0, 1000.0};
  std::vector<double> state(times.size(), 0.0);
  std::vector<double> angle(400000);
  double theta = 0.0;
  for (double& a : angle) {
    double rate = 0.0;
    for (std::size_t i = 0; i < times.size(); ++i) {
      const double phi = std::exp(-tau0 / times[i]);
      state[i] = phi * state[i] + std::sqrt(1.0 - phi * phi) * b * g.next();
      rate += state[i];
    }
    theta += rate * tau0;
    a = theta;
  }
  const AllanResult r = allanDeviation(angle, tau0);
  ASSERT_TRUE(r.bias_instability.identified);
  // The plateau of this process sits near 1.04e-6 rad/s from 5 s to 150 s; B is its bottom / 0.664.
  EXPECT_LE(r.bias_instability.tau_min, 5.0);
  EXPECT_GE(r.bias_instability.tau_max, 100.0);
  double lowest = INFINITY;
  for (const AllanPoint& p : r.curve) {
    if (p.tau >= r.bias_instability.tau_min && p.tau <= r.bias_instability.tau_max)
      lowest = std::min(lowest, p.deviation);
  }
  EXPECT_DOUBLE_EQ(r.bias_instability.value, lowest / 0.664);
  EXPECT_NEAR(r.bias_instability.value, 1.04e-6 / 0.664, 0.06 * 1.04e-6 / 0.664);
}

TEST(AllanDeviationTest, RateRandomWalkHasSlopePlusHalfAndGivesK) {
  // A rate that random-walks: sigma(tau) = K sqrt(tau / 3), so sigma(3 s) = K.
  GaussianNoise g(4);
  const double k = 2e-6, tau0 = 0.05;  // rad/s/sqrt(s)
  std::vector<double> angle(400000);
  double rate = 0.0, theta = 0.0;
  for (double& a : angle) {
    rate += k * std::sqrt(tau0) * g.next();
    theta += rate * tau0;
    a = theta;
  }
  const AllanResult r = allanDeviation(angle, tau0);
  ASSERT_TRUE(r.rate_random_walk.identified);
  EXPECT_NEAR(r.rate_random_walk.value, k, 0.1 * k);
  EXPECT_FALSE(r.angle_random_walk.identified);
  EXPECT_FALSE(r.bias_instability.identified);
}

TEST(AllanDeviationTest, WhiteRateNoiseShowsNoRateRandomWalk) {
  GaussianNoise g(5);
  const double n = 1e-4, tau0 = 0.01;
  std::vector<double> angle(200000);
  double theta = 0.0;
  for (double& a : angle) {
    theta += n * std::sqrt(tau0) * g.next();
    a = theta;
  }
  EXPECT_FALSE(allanDeviation(angle, tau0).rate_random_walk.identified);
}

TEST(AllanDeviationTest, TooShortGivesNothing) {
  EXPECT_TRUE(allanDeviation({1.0, 2.0, 3.0}, 0.1).curve.empty());
  EXPECT_TRUE(allanDeviation(std::vector<double>(100, 0.0), 0.0).curve.empty());
}

}  // namespace
}  // namespace core
}  // namespace hrg_gyro
