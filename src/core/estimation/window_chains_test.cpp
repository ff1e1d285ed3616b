// Samples into window means chain by chain, and the increments of each chain.
#include "hrg_gyro/core/estimation/window_chains.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace hrg_gyro {
namespace core {
namespace {

/// A chain of `seconds` s at 1 kHz: theta and phi linear in time.
std::vector<WindowIncrement> chain(WindowChains* chains, const IncrementModel& model, int group, double start,
                                   double seconds, double rate, bool with_rate) {
  chains->start(group, 0.5);
  for (int i = 0; i < static_cast<int>(seconds * 1000); ++i) {
    const double t = i * 1e-3, phi = rate * t;
    chains->add(model, toNanoseconds(start + t), 0.2 - 0.56 * phi, phi, with_rate ? phi : NAN, -1, 0.0);
  }
  return chains->end(model);
}

TEST(WindowChainsTest, IncrementsOfConsecutiveWindowMeansNeverSpanTwoChains) {
  const IncrementModel model({2}, {2}, 0, 0);
  WindowChains chains(model);
  const std::vector<WindowIncrement> first = chain(&chains, model, 0, 1.0, 10.0, 0.05, false);
  const std::vector<WindowIncrement> second = chain(&chains, model, 3, 20.0, 5.0, -0.05, false);
  ASSERT_EQ(first.size(), 18u);  // 20 windows of 0.5 s, the last one left out
  ASSERT_EQ(second.size(), 8u);
  EXPECT_FALSE(first[0].follows);
  EXPECT_TRUE(first[1].follows);
  EXPECT_FALSE(second[0].follows);
  EXPECT_EQ(second[0].group, 3);
  for (const WindowIncrement& inc : first) {
    EXPECT_NEAR(inc.dt, 0.5, 1e-12);
    EXPECT_NEAR(inc.dphi, 0.025, 1e-12);
    EXPECT_NEAR(inc.dw(0), 0.025, 1e-12);                 // Phi0 moves by the table's step
    EXPECT_NEAR(inc.dw(model.columns()), -0.014, 1e-12);  // y: the wave angle's step
    EXPECT_EQ(inc.count_before, 500.0);
  }
  // The second chain's mid times count from the session's first sample, not its own.
  EXPECT_NEAR(second[0].t_mid, 19.0 + 0.4995, 1e-9);
  EXPECT_NEAR(chains.lastSessionTime(), 19.0 + 4.999, 1e-9);
  EXPECT_EQ(chains.sessionOrigin(), toNanoseconds(1.0));
}

TEST(WindowChainsTest, WeighsTheRateIntegralAgainstANoisyAngle) {
  // The logged angle noisy, the rate integral clean: the table angle leans on the integral.
  const IncrementModel model({2}, {2}, 0, 0);
  WindowChains clean(model), noisy(model);
  std::mt19937_64 random(4);
  std::normal_distribution<double> normal(0.0, 1.0);
  for (int c = 0; c < 4; ++c) {
    for (WindowChains* chains : {&clean, &noisy}) {
      chains->start(c, 0.5);
      for (int i = 0; i < 20000; ++i) {
        const double t = i * 1e-3, phi = 0.05 * t;
        const double logged = chains == &noisy ? phi + 1e-4 * normal(random) : phi;
        chains->add(model, toNanoseconds(100.0 * c + t), 0.2 - 0.56 * phi, logged, phi, -1, 0.0);
      }
      chains->end(model);
    }
  }
  EXPECT_EQ(clean.angleWeight(), 1.0);  // both clean: the angle, as without a rate
  EXPECT_LT(noisy.angleWeight(), 0.1);
  EXPECT_THROW(noisy.add(model, toNanoseconds(999.0), 0.0, 0.0, NAN, -1, 0.0), std::logic_error);
  EXPECT_THROW(noisy.start(0, 0.0), std::invalid_argument);
}

}  // namespace
}  // namespace core
}  // namespace hrg_gyro
