// The unified harmonic model, its recurrence basis and the frequency interpolation.
#include "hrg_gyro/core/model/harmonic_model.h"

#include <gtest/gtest.h>

#include "hrg_gyro/core/common/units.h"
#include "hrg_gyro/core/model/harmonic_basis.h"

namespace hrg_gyro {
namespace core {
namespace {

TEST(HarmonicBasisTest, RecurrenceMatchesDirectEvaluation) {
  HarmonicBasis basis(2, 16);
  for (double theta : {-1234.5, -3.0, 0.0, 0.1, 2.5, 987.6}) {
    basis.evaluate(theta);
    for (int k = 0; k <= 16; k += 2) {
      EXPECT_NEAR(basis.cosOf(k), std::cos(k * theta), 1e-12) << k;
      EXPECT_NEAR(basis.sinOf(k), std::sin(k * theta), 1e-12) << k;
    }
  }
  EXPECT_THROW(HarmonicBasis(2, 3), std::invalid_argument);
}

TEST(HarmonicModelTest, EvaluatesTheFormula) {
  const HarmonicModel m({2, 4, 8}, -0.56, {1e-3, -2e-4, 3e-5}, {-4e-4, 5e-4, 0.0});
  for (double th = -7.0; th < 7.0; th += 0.37) {
    const double expected = -0.56 + 1e-3 * std::cos(2 * th) - 2e-4 * std::cos(4 * th) + 3e-5 * std::cos(8 * th) -
                            4e-4 * std::sin(2 * th) + 5e-4 * std::sin(4 * th);
    EXPECT_NEAR(m(th), expected, 1e-15);
  }
  EXPECT_EQ(m.orderStep(), 2);
  EXPECT_EQ(m.maxOrder(), 8);
  EXPECT_FALSE(m.frequencyDependent());
}

TEST(HarmonicModelTest, PeakDeviationOfOneHarmonicIsItsAmplitude) {
  const HarmonicModel m({4}, -0.5, {3e-4}, {4e-4});
  EXPECT_NEAR(m.peakDeviation(), 5e-4, 5e-4 * 2e-3);
  EXPECT_EQ(HarmonicModel(-0.5).peakDeviation(), 0.0);
}

TEST(FrequencyInterpolatorTest, SplineInterpolatesNodesAndIsExactForLines) {
  const FrequencyInterpolator spline({4990.0, 4995.0, 5003.0, 5010.0, 5020.0});
  std::vector<double> w(spline.size());
  for (std::size_t j = 0; j < spline.size(); ++j) {
    spline.weights(spline.nodes()[j], w.data());
    for (std::size_t k = 0; k < w.size(); ++k) EXPECT_NEAR(w[k], j == k ? 1.0 : 0.0, 1e-12);
  }
  for (double f = 4990.0; f <= 5020.0; f += 0.7) {
    spline.weights(f, w.data());
    double sum = 0.0, line = 0.0;
    for (std::size_t k = 0; k < w.size(); ++k) {
      sum += w[k];
      line += w[k] * (3.0 + 0.25 * (spline.nodes()[k] - 5000.0));
    }
    EXPECT_NEAR(sum, 1.0, 1e-12);
    EXPECT_NEAR(line, 3.0 + 0.25 * (f - 5000.0), 1e-9);
  }
}

TEST(FrequencyInterpolatorTest, NaturalSplineMatchesSmoothFunctionAndHoldsOutside) {
  std::vector<double> nodes;
  for (int j = 0; j <= 10; ++j) nodes.push_back(4990.0 + 2.0 * j);
  const FrequencyInterpolator spline(nodes);
  std::vector<double> w(nodes.size());
  auto g = [](double f) { return std::sin((f - 4990.0) / 6.0); };
  for (double f = 4994.0; f <= 5006.0; f += 0.3) {
    spline.weights(f, w.data());
    double v = 0.0;
    for (std::size_t k = 0; k < w.size(); ++k) v += w[k] * g(nodes[k]);
    EXPECT_NEAR(v, g(f), 2e-4);
  }
  spline.weights(4000.0, w.data());
  EXPECT_EQ(w[0], 1.0);
  spline.weights(6000.0, w.data());
  EXPECT_EQ(w.back(), 1.0);
  EXPECT_FALSE(spline.inRange(6000.0));
  EXPECT_THROW(FrequencyInterpolator({5000.0, 4990.0}), std::invalid_argument);
}

TEST(HarmonicModelTest, FrequencyDependentCoefficients) {
  const FrequencyInterpolator interp({4990.0, 5000.0, 5010.0}, Interpolation::kPiecewiseLinear);
  Eigen::MatrixXd values(3, 3);
  values << -0.56, -0.55, -0.54,  // mean
      1e-3, 2e-3, 3e-3,           // cos 2
      0.0, -1e-3, -2e-3;          // sin 2
  const HarmonicModel m({2}, interp, values);
  EXPECT_TRUE(m.frequencyDependent());
  std::vector<double> c(3);
  m.coefficientsAt(4995.0, c.data());
  EXPECT_NEAR(c[0], -0.555, 1e-15);
  EXPECT_NEAR(c[1], 1.5e-3, 1e-15);
  EXPECT_NEAR(c[2], -0.5e-3, 1e-15);
  EXPECT_NEAR(m(0.3, 5010.0), -0.54 + 3e-3 * std::cos(0.6) - 2e-3 * std::sin(0.6), 1e-15);
  EXPECT_NEAR(m.meanAt(NAN), -0.56, 1e-15);  // unknown frequency: the first node
}

}  // namespace
}  // namespace core
}  // namespace hrg_gyro
