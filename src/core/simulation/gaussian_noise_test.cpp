#include "hrg_gyro/core/simulation/gaussian_noise.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

namespace hrg_gyro {
namespace core {
namespace {

// Both methods pass every test.
class GaussianNoiseTest : public ::testing::TestWithParam<GaussianNoise::Method> {};
INSTANTIATE_TEST_SUITE_P(Methods, GaussianNoiseTest,
                         ::testing::Values(GaussianNoise::Method::kPolar, GaussianNoise::Method::kZiggurat));

TEST_P(GaussianNoiseTest, HasUnitNormalMoments) {
  GaussianNoise g(123, GetParam());
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

// The whole distribution, not only its moments: the empirical CDF against the normal CDF on a grid
// finer than the ziggurat's narrowest strips near 0, and the frequency of the tail beyond the bottom
// strip's edge r = 3.654 (drawn by its own method) and beyond 4.5.
TEST_P(GaussianNoiseTest, FollowsTheNormalDistributionIncludingItsTails) {
  GaussianNoise g(2026, GetParam());
  const int n = 4000000;
  std::vector<double> x(n);
  for (double& v : x) v = g.next();
  std::sort(x.begin(), x.end());
  auto normalCdf = [](double t) { return 0.5 * std::erfc(-t / std::sqrt(2.0)); };
  for (int k = -80; k <= 80; ++k) {
    const double t = 0.05 * k;
    const double empirical = static_cast<double>(std::lower_bound(x.begin(), x.end(), t) - x.begin()) / n;
    const double p = normalCdf(t);
    EXPECT_NEAR(empirical, p, 5.0 * std::sqrt(p * (1.0 - p) / n) + 1e-7) << "at " << t;
  }
  auto countBeyond = [&](double t) {
    return static_cast<double>((x.end() - std::upper_bound(x.begin(), x.end(), t)) +
                               (std::lower_bound(x.begin(), x.end(), -t) - x.begin()));
  };
  for (double t : {3.6541528853610088, 4.5}) {
    const double expected = n * std::erfc(t / std::sqrt(2.0));
    EXPECT_NEAR(countBeyond(t), expected, 5.0 * std::sqrt(expected)) << "beyond " << t;
  }
  EXPECT_GT(x.back(), 4.5);
  EXPECT_LT(x.front(), -4.5);
}

TEST_P(GaussianNoiseTest, IsReproducibleBySeed) {
  GaussianNoise a(5, GetParam()), b(5, GetParam()), c(6, GetParam());
  bool differs = false;
  for (int i = 0; i < 1000; ++i) {
    const double x = a.next();
    EXPECT_EQ(x, b.next());
    differs = differs || x != c.next();
  }
  EXPECT_TRUE(differs);
}

TEST_P(GaussianNoiseTest, ConsecutiveValuesAreUncorrelated) {
  GaussianNoise g(9, GetParam());
  const int n = 500000;
  double prev = g.next(), sum = 0;
  for (int i = 0; i < n; ++i) {
    const double x = g.next();
    sum += x * prev;
    prev = x;
  }
  EXPECT_NEAR(sum / n, 0.0, 5 / std::sqrt(n));
}

// fill() is the synthesizer's way of drawing a period's noise: it must be the very stream next()
// gives, whatever the counts (odd ones leave a spare deviate behind) and wherever the stream stands.
TEST_P(GaussianNoiseTest, FillGivesTheSameStreamAsNext) {
  GaussianNoise one(13, GetParam()), many(13, GetParam());
  std::vector<double> buffer;
  for (int n : {64, 1, 7, 0, 128, 200, 3, 64, 65, 2}) {
    buffer.assign(static_cast<std::size_t>(n), 0.0);
    many.fill(buffer.data(), n);
    for (int i = 0; i < n; ++i) ASSERT_EQ(buffer[static_cast<std::size_t>(i)], one.next()) << n << ", " << i;
  }
  EXPECT_EQ(many.next(), one.next());  // and the generators end in the same state
  EXPECT_EQ(many.uniform(), one.uniform());
}

TEST(GaussianNoiseMethodsTest, TheTwoMethodsAreDifferentStreamsFromOneSeed) {
  GaussianNoise polar(5), ziggurat(5, GaussianNoise::Method::kZiggurat);
  int equal = 0;
  for (int i = 0; i < 1000; ++i) equal += polar.next() == ziggurat.next() ? 1 : 0;
  EXPECT_LT(equal, 10);
}

}  // namespace
}  // namespace core
}  // namespace hrg_gyro
