// The dual-rate method on fast angle-level sessions (docs/math.md, 'Calibration methods'), and the
// quality gates that refuse too little or too poor data.
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>

#include "core/testing/angle_level_session.h"
#include "core/testing/method_test_settings.h"

namespace hrg_gyro {
namespace core {
namespace {

TEST(DualRateTest, RecoversKAndDAndCancelsTheDrift) {
  const testing::AngleLevelGyro g = testing::referenceGyro();
  const CalibrationOutcome o = testing::calibrateAngleLevel(g, testing::dualRateProfile(0.05, -0.05, 120.0),
                                                            testing::methodSettings(CalibrationMethodKind::kDualRate),
                                                            testing::referencePrior());
  ASSERT_TRUE(o.accepted) << o.reason;
  const HarmonicFitResult& k = o.scale_factor[0];
  const HarmonicFitResult& d = o.drift[0];
  EXPECT_NEAR(k.mean, -0.56, 1e-7);
  EXPECT_NEAR(k.cos[0], -6e-4, 1e-7);  // the drift cancels: errors below 1e-7
  EXPECT_NEAR(k.sin[0], 4e-4, 1e-7);
  EXPECT_NEAR(k.cos[1], 2e-3, 1e-7);
  EXPECT_NEAR(d.mean, 1e-5, 1e-9);
  EXPECT_NEAR(d.cos[0], 2e-5, 1e-9);
  EXPECT_NEAR(d.sin[0], -1e-5, 1e-9);
  EXPECT_NEAR(o.coverage, 1.0, 1e-12);
  EXPECT_EQ(o.plateaus.size(), 2u);
  EXPECT_TRUE(o.parameters.scale_factor == toModel(k));
  EXPECT_EQ(o.parameters.calibration.method, ParameterOrigin::calibratedBy(CalibrationMethodKind::kDualRate));
  EXPECT_GT(o.error_bound, 0.0);
}

TEST(DualRateTest, AFastShortPlateauCoversThetaWithItsOwnWindow) {
  // At 0.4 rad/s the wave crosses a theta bin in 0.11 s: 30 s plateaus sweep each bin about 0.45 s
  // in all, less than a quarter of the 2 s `window` but many times the 0.27 s window these rates use.
  // Coverage and the fit's bins are judged against the window in use.
  const testing::AngleLevelGyro g = testing::referenceGyro();
  const CalibrationOutcome o = testing::calibrateAngleLevel(g, testing::dualRateProfile(0.4, -0.4, 30.0),
                                                            testing::methodSettings(CalibrationMethodKind::kDualRate),
                                                            testing::referencePrior());
  ASSERT_TRUE(o.accepted) << o.reason;
  EXPECT_GE(o.coverage, 0.95);
  EXPECT_LE(testing::peakErrorPpm(o.parameters.scale_factor, g.k), 1.0);
}

TEST(DualRateTest, NonFiniteWaveAnglesAreSkipped) {
  const testing::AngleLevelGyro g = testing::referenceGyro();
  CalibrationSession session(testing::methodSettings(CalibrationMethodKind::kDualRate), testing::referencePrior());
  long i = 0;
  testing::runAngleLevel(g, testing::dualRateProfile(0.05, -0.05, 120.0),
                         [&](Nanoseconds t, double angle, double rate, double theta) {
                           session.addRotationRecord(t, angle, rate);
                           session.addWave(t, ++i % 997 == 0 ? NAN : theta, NAN);
                         });
  const CalibrationOutcome o = session.finish();
  ASSERT_TRUE(o.accepted) << o.reason;
  EXPECT_NEAR(o.scale_factor[0].mean, -0.56, 1e-7);
  EXPECT_NEAR(o.scale_factor[0].cos[1], 2e-3, 1e-7);
}

TEST(DualRateTest, SameSignRatesWorkToo) {
  const testing::AngleLevelGyro g = testing::referenceGyro();
  const CalibrationOutcome o = testing::calibrateAngleLevel(g, testing::dualRateProfile(0.05, 0.15, 120.0),
                                                            testing::methodSettings(CalibrationMethodKind::kDualRate),
                                                            testing::referencePrior());
  ASSERT_TRUE(o.accepted) << o.reason;
  EXPECT_NEAR(o.scale_factor[0].cos[1], 2e-3, 1e-7);
  EXPECT_NEAR(o.drift[0].cos[0], 2e-5, 1e-8);
}

TEST(DualRateTest, StandardErrorsDescribeTheActualErrors) {
  // With white angle noise, (estimate - truth) / std over the harmonics behaves like N(0, 1).
  double z2 = 0.0;
  int n = 0;
  for (std::uint64_t seed = 1; seed <= 4; ++seed) {
    testing::AngleLevelGyro g = testing::referenceGyro();
    g.noise = 1.1e-5;
    g.seed = seed;
    const CalibrationOutcome o = testing::calibrateAngleLevel(g, testing::dualRateProfile(0.05, -0.05, 120.0),
                                                              testing::methodSettings(CalibrationMethodKind::kDualRate),
                                                              testing::referencePrior());
    ASSERT_TRUE(o.accepted) << o.reason;
    const HarmonicFitResult& k = o.scale_factor[0];
    const double truth_cos[] = {-6e-4, 2e-3}, truth_sin[] = {4e-4, 0.0};
    for (int j = 0; j < 2; ++j) {
      z2 +=
          std::pow((k.cos[j] - truth_cos[j]) / k.cos_std[j], 2) + std::pow((k.sin[j] - truth_sin[j]) / k.sin_std[j], 2);
      n += 2;
    }
  }
  // 16 squared z-scores: their mean is 1 +- 0.35 (1 sigma) if the errors are honest.
  EXPECT_GT(z2 / n, 0.2);
  EXPECT_LT(z2 / n, 2.5);
}

TEST(QualityGatesTest, RefuseInsufficientData) {
  const testing::AngleLevelGyro g = testing::referenceGyro();
  auto gateFailed = [](const CalibrationOutcome& o, const std::string& name) {
    for (const GateResult& r : o.gates) {
      if (r.name == name) return !r.passed;
    }
    return false;
  };
  // One rate only.
  TurntableProfile one;
  one.append(5.0, 0.0, 0.0, "rest");
  one.append(0.1, 0.0, 0.5, "ramp");
  one.append(150.0, 0.05, 0.0, "turn");
  CalibrationOutcome o = testing::calibrateAngleLevel(g, one, testing::methodSettings(CalibrationMethodKind::kDualRate),
                                                      testing::referencePrior());
  EXPECT_FALSE(o.accepted);
  EXPECT_TRUE(gateFailed(o, "plateau_groups")) << o.reason;
  // Too short for theta to cover pi.
  o = testing::calibrateAngleLevel(g, testing::dualRateProfile(0.05, -0.05, 40.0),
                                   testing::methodSettings(CalibrationMethodKind::kDualRate),
                                   testing::referencePrior());
  EXPECT_FALSE(o.accepted);
  EXPECT_TRUE(gateFailed(o, "coverage")) << o.reason;
  EXPECT_NE(o.reason.find("coverage"), std::string::npos);
  // Rates too close.
  o = testing::calibrateAngleLevel(g, testing::dualRateProfile(0.05, 0.055, 130.0),
                                   testing::methodSettings(CalibrationMethodKind::kDualRate),
                                   testing::referencePrior());
  EXPECT_FALSE(o.accepted);
  EXPECT_TRUE(gateFailed(o, "rate_separation")) << o.reason;
  // A noisy reported rate does not matter where the angle is logged: the logged angle is integrated.
  testing::AngleLevelGyro noisy = g;
  noisy.rate_noise = 1e-4;
  CalibrationSettings loose = testing::methodSettings(CalibrationMethodKind::kDualRate);
  loose.plateau.rate_tolerance = 1e-3;
  o = testing::calibrateAngleLevel(noisy, testing::dualRateProfile(0.05, -0.05, 120.0), loose,
                                   testing::referencePrior());
  EXPECT_TRUE(o.accepted) << o.reason;
  EXPECT_NEAR(o.scale_factor[0].cos[1], 2e-3, 1e-7);
  // A noisy logged angle does when the logged rate is no cleaner (here its integral wanders more than
  // the angle scatters): the gate judges the table's effect on the K harmonics.
  testing::TableImperfections shaky;
  shaky.encoder_noise = 1e-3;
  testing::AngleLevelGyro rate_noisier = g;
  rate_noisier.rate_noise = 0.01;
  CalibrationSettings smoothed = loose;  // long enough a span that the plateaus are still found
  smoothed.plateau.smoothing_span = 10.0;
  smoothed.gates.max_table_error = 5e-6;  // 1 mrad of encoder noise costs the K harmonics ~10 ppm
  const CalibrationOutcome clean_rate = testing::calibrateTableSession(
      g, shaky, testing::dualRateProfile(0.05, -0.05, 150.0), smoothed, testing::referencePrior());
  // With the drive's own rate logged, its integral carries the shape and the angle only each
  // plateau's slope: the 1 mrad hardly matters.
  EXPECT_TRUE(clean_rate.accepted) << clean_rate.reason;
  o = testing::calibrateTableSession(rate_noisier, shaky, testing::dualRateProfile(0.05, -0.05, 150.0), smoothed,
                                     testing::referencePrior());
  EXPECT_FALSE(o.accepted);
  EXPECT_TRUE(gateFailed(o, "table_error")) << o.reason;
  for (const auto& gate : o.gates) {
    if (gate.name == "table_error") std::cout << "1 mrad encoder noise: table_error " << gate.value * 1e6 << " ppm\n";
  }
  EXPECT_NE(o.reason.find("table angle errors add"), std::string::npos) << o.reason;
  // Too few samples.
  CalibrationSettings many = testing::methodSettings(CalibrationMethodKind::kDualRate);
  many.gates.min_samples = 10000000;
  o = testing::calibrateAngleLevel(g, testing::dualRateProfile(0.05, -0.05, 120.0), many, testing::referencePrior());
  EXPECT_FALSE(o.accepted);
  EXPECT_TRUE(gateFailed(o, "samples"));
}

}  // namespace
}  // namespace core
}  // namespace hrg_gyro
