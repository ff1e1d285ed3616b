// The compensation step recovers the body rotation from a wave angle that obeys
// d theta = K(theta) (d alpha + Omega_E dt) + D(theta) dt (docs/math.md, 'Dynamics and
// compensation').
#include "hrg_gyro/core/processing/compensator.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "core/testing/same_bits.h"

namespace hrg_gyro {
namespace core {
namespace {

std::shared_ptr<GyroParameters> makeParameters() {
  auto p = std::make_shared<GyroParameters>();
  p->scale_factor = HarmonicModel({2, 4}, -0.56, {-6e-4, 2e-3}, {4e-4, 0.0});
  p->drift = HarmonicModel({2}, 1e-5, {2e-5}, {-1e-5});
  p->earth_rate.latitude = 0.9;
  return p;
}

// theta(t) by RK4 with a fine step, for a table turning at `rate`.
double integrateTheta(const GyroParameters& p, double theta, double rate, double dt, int substeps) {
  const double earth = p.earth_rate.verticalRate();
  auto f = [&](double th) { return p.scale_factor(th) * (rate + earth) + p.drift(th); };
  const double h = dt / substeps;
  for (int i = 0; i < substeps; ++i) {
    const double k1 = f(theta), k2 = f(theta + h / 2 * k1), k3 = f(theta + h / 2 * k2), k4 = f(theta + h * k3);
    theta += h / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
  }
  return theta;
}

TEST(CompensatorTest, RecoversTheInertialAndEarthFixedAngle) {
  const auto p = makeParameters();
  Compensator comp(p);
  const double dt = 1e-3, rate = 0.05;
  double theta = 0.3, alpha = 0.0, alpha_fixed = 0.0;
  const int steps = 200000;  // 200 s: theta sweeps more than pi
  for (int i = 0; i < steps; ++i) {
    const double next = integrateTheta(*p, theta, rate, dt, 4);
    const AngleIncrement inc = comp.step(theta, next, dt, NAN);
    alpha += inc.dalpha;
    alpha_fixed += inc.dalpha_earth_fixed;
    theta = next;
  }
  const double t = steps * dt;
  EXPECT_LT(theta, 0.3 - kPi);  // K0 < 0: a positive rotation turns theta negative
  // The midpoint rule errs at O(dtheta^3 K''): far below 1e-9 rad here.
  EXPECT_NEAR(alpha, (rate + p->earth_rate.verticalRate()) * t, 1e-9);
  EXPECT_NEAR(alpha_fixed, rate * t, 1e-9);
}

TEST(CompensatorTest, UsesMidpointAndReportsWhatItUsed) {
  const auto p = makeParameters();
  Compensator comp(p);
  const AngleIncrement inc = comp.step(0.2, 0.1, 0.01, NAN);
  EXPECT_DOUBLE_EQ(inc.theta_mid, 0.15);
  EXPECT_DOUBLE_EQ(inc.scale_factor, p->scale_factor(0.15));
  EXPECT_DOUBLE_EQ(inc.drift, p->drift(0.15));
  EXPECT_DOUBLE_EQ(inc.dalpha, (-0.1 - p->drift(0.15) * 0.01) / p->scale_factor(0.15));
}

TEST(CompensatorTest, EvaluatesFrequencyDependentModelsAtTheGivenFrequency) {
  auto p = std::make_shared<GyroParameters>();
  Eigen::MatrixXd k(3, 2);
  k << -0.56, -0.50, 1e-3, 2e-3, 0.0, 0.0;
  p->scale_factor = HarmonicModel({2}, FrequencyInterpolator({4990.0, 5010.0}), k);
  Compensator comp(p);
  for (double f : {4990.0, 5000.0, 5010.0, 5000.0}) {
    const AngleIncrement inc = comp.step(0.0, 1e-3, 1e-3, f);
    EXPECT_NEAR(inc.scale_factor, p->scale_factor(5e-4, f), 1e-15) << f;
  }
}

TEST(CompensatorTest, StepsOfABatchEqualOneStepEachBitForBit) {
  // Four at a time where the models allow it (fixed coefficients, even orders), one at a time
  // otherwise; batches whose length is not a multiple of four leave a remainder.
  Eigen::MatrixXd k_nodes(3, 2);
  k_nodes << -0.56, -0.50, 1e-3, 2e-3, -2e-4, 1e-4;
  const HarmonicModel scale_factors[] = {
      HarmonicModel({2, 4, 6, 8}, -0.56, {1e-4, 5e-5, 3e-5, 2e-5}, {-5e-5, 0, 1e-5, 0}),  // in lanes
      HarmonicModel({4, 8}, -0.56, {1e-4, 2e-5}, {-5e-5, 1e-5}),                          // orders 4 apart: lanes
      HarmonicModel({1, 2}, -0.56, {1e-4, 2e-5}, {-5e-5, 1e-5}),                          // odd orders: one by one
      HarmonicModel({2}, FrequencyInterpolator({4990.0, 5010.0}), k_nodes)};              // K(theta, f): one by one
  std::vector<std::shared_ptr<GyroParameters>> cases;
  for (const HarmonicModel& scale_factor : scale_factors) {
    auto p = std::make_shared<GyroParameters>();
    p->earth_rate.latitude = 0.9;
    p->scale_factor = scale_factor;
    p->drift = HarmonicModel({2, 4}, 1e-5, {2e-5, 1e-6}, {-1e-5, 0.0});
    cases.push_back(p);
  }
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> angle(-50.0, 50.0), step(-0.01, 0.01), frequency(4985.0, 5015.0);
  for (std::size_t c = 0; c < cases.size(); ++c) {
    Compensator single(cases[c]), batched(cases[c]);
    EXPECT_EQ(ModelPairEvaluator(cases[c]->scale_factor, cases[c]->drift).lanesApply(), c < 2) << c;
    for (std::size_t length : {1u, 3u, 4u, 7u, 32u}) {
      StepBatch batch;
      std::vector<AngleIncrement> expected(length), got(length);
      for (std::size_t i = 0; i < length; ++i) {
        const double previous = angle(rng), theta = previous + step(rng), f = frequency(rng);
        const double dt = 1e-3 * (1.0 + 1e-3 * i);
        expected[i] = single.step(previous, theta, dt, f, std::cos(previous), std::sin(previous), std::cos(theta),
                                  std::sin(theta));
        batch.add(previous, theta, dt, f, std::cos(previous), std::sin(previous), std::cos(theta), std::sin(theta),
                  &got[i]);
      }
      batched.steps(&batch);
      EXPECT_EQ(batch.size, 0u);
      for (std::size_t i = 0; i < length; ++i) {
        EXPECT_TRUE(sameIncrementBits(expected[i], got[i])) << "case " << c << ", length " << length << ", step " << i;
      }
    }
  }
}

}  // namespace
}  // namespace core
}  // namespace hrg_gyro
