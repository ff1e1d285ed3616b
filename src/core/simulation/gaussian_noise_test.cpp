#include "hrg_gyro/core/simulation/gaussian_noise.h"

#include <gtest/gtest.h>

namespace hrg_gyro {
namespace core {
namespace {

TEST(GaussianNoiseTest, HasUnitNormalMoments) {
  GaussianNoise g(123);
  const int n = 2000000;
  double m1 = 0, m2 = 0, m4 = 0, tail = 0;
  for (int i = 0; i < n; ++i) {
    const double x = g.next();
    m1 += x;
    m2 += x * x;
    m4 += x * x * x * x;
    tail += std::abs(x) > 3.0 ? 1.0 : 0.0;
  }
  m1 /= n;
  m2 /= n;
  m4 /= n;
  EXPECT_NEAR(m1, 0.0, 5 / std::sqrt(n));
  EXPECT_NEAR(m2, 1.0, 5 * std::sqrt(2.0 / n));
  EXPECT_NEAR(m4, 3.0, 0.03);                // kurtosis of a normal
  EXPECT_NEAR(tail / n, 0.0026998, 0.0003);  // P(|x| > 3)
}

TEST(GaussianNoiseTest, IsReproducibleBySeed) {
  GaussianNoise a(5), b(5), c(6);
  bool differs = false;
  for (int i = 0; i < 1000; ++i) {
    const double x = a.next();
    EXPECT_EQ(x, b.next());
    differs = differs || x != c.next();
  }
  EXPECT_TRUE(differs);
}

TEST(GaussianNoiseTest, ConsecutiveValuesAreUncorrelated) {
  GaussianNoise g(9);
  const int n = 500000;
  double prev = g.next(), sum = 0;
  for (int i = 0; i < n; ++i) {
    const double x = g.next();
    sum += x * prev;
    prev = x;
  }
  EXPECT_NEAR(sum / n, 0.0, 5 / std::sqrt(n));
}

}  // namespace
}  // namespace core
}  // namespace hrg_gyro
