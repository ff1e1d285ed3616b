// The K and D pair evaluator: both of its paths agree with the models they evaluate.
#include "hrg_gyro/core/model/model_pair_evaluator.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace hrg_gyro {
namespace core {
namespace {

// K and D with every order a multiple of `step` up to 8 steps, some orders left out of one model.
HarmonicModel scaleFactorModel(int step) {
  return HarmonicModel({step, 2 * step, 4 * step, 8 * step}, -0.56, {1e-3, -2e-4, 3e-5, 4e-6},
                       {-4e-4, 5e-4, 0.0, -7e-6});
}
HarmonicModel driftModel(int step) { return HarmonicModel({step, 3 * step}, 2e-5, {-3e-6, 1e-6}, {6e-6, -2e-7}); }

TEST(ModelPairEvaluatorTest, DoubleAnglePathEqualsTheModels) {
  // The per-sample path builds every order from cos 2 theta, sin 2 theta by a recurrence in
  // registers; the other path goes through the basis. Both must equal the models' own evaluation.
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> angle(-500.0, 500.0);
  for (int step : {1, 2, 4}) {
    const HarmonicModel k = scaleFactorModel(step), d = driftModel(step);
    ModelPairEvaluator evaluator(k, d);
    EXPECT_FALSE(evaluator.frequencyDependent());
    for (int i = 0; i < 200; ++i) {
      const double theta = angle(rng);
      double k1, d1, k2, d2;
      evaluator.evaluate(theta, 5000.0, &k1, &d1);
      evaluator.evaluate(theta, std::cos(2.0 * theta), std::sin(2.0 * theta), 5000.0, &k2, &d2);
      EXPECT_NEAR(k1, k(theta), 1e-15) << step << " " << theta;
      EXPECT_NEAR(d1, d(theta), 1e-18) << step << " " << theta;
      EXPECT_NEAR(k2, k(theta), 1e-14) << step << " " << theta;
      EXPECT_NEAR(d2, d(theta), 1e-17) << step << " " << theta;
    }
  }
}

TEST(ModelPairEvaluatorTest, FollowsTheFrequency) {
  // Coefficients re-interpolated when the frequency changes, kept while it does not, and the first
  // node used while the frequency is unknown, as the model itself does.
  const FrequencyInterpolator interp({4990.0, 5000.0, 5010.0}, Interpolation::kPiecewiseLinear);
  Eigen::MatrixXd k_values(3, 3), d_values(3, 3);
  k_values << -0.56, -0.55, -0.54, 1e-3, 2e-3, 3e-3, 0.0, -1e-3, -2e-3;
  d_values << 1e-5, 2e-5, 3e-5, -1e-6, 0.0, 1e-6, 2e-6, 2e-6, 2e-6;
  const HarmonicModel k({2}, interp, k_values), d({2}, interp, d_values);
  ModelPairEvaluator evaluator(k, d);
  EXPECT_TRUE(evaluator.frequencyDependent());
  const double unknown = std::nan("");
  for (double f : {4995.0, 4995.0, 5007.5, unknown, unknown, 5000.0}) {
    for (double theta : {-3.0, 0.3, 2.0}) {
      double k1, d1, k2, d2;
      evaluator.evaluate(theta, f, &k1, &d1);
      evaluator.evaluate(theta, std::cos(2.0 * theta), std::sin(2.0 * theta), f, &k2, &d2);
      EXPECT_NEAR(k1, k(theta, f), 1e-15) << f;
      EXPECT_NEAR(d1, d(theta, f), 1e-18) << f;
      EXPECT_NEAR(k2, k(theta, f), 1e-15) << f;
      EXPECT_NEAR(d2, d(theta, f), 1e-18) << f;
    }
  }
}

}  // namespace
}  // namespace core
}  // namespace hrg_gyro
