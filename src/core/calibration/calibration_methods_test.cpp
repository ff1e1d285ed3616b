// The calibration methods on fast angle-level sessions (docs/math.md, 'Calibration methods'), the
// session's stream synchronisation, and the quality gates.
#include <gtest/gtest.h>

#include <deque>

#include "core/testing/angle_level_session.h"

namespace hrg_gyro {
namespace core {
namespace {

using testing::AngleLevelGyro;
using testing::calibrateAngleLevel;
using testing::dualRateProfile;
using testing::referenceGyro;

GyroParameters priorFor(const AngleLevelGyro& g) {
  GyroParameters p;
  p.earth_rate.latitude = 0.9;
  (void)g;
  return p;
}

CalibrationSettings settings(const std::string& method) {
  CalibrationSettings s;
  s.method = parseCalibrationMethod(method);
  s.scale_factor_orders = {2, 4};
  s.drift_orders = {2};
  return s;
}

TEST(DualRateTest, RecoversKAndDAndCancelsTheDrift) {
  const AngleLevelGyro g = referenceGyro();
  const CalibrationOutcome o =
      calibrateAngleLevel(g, dualRateProfile(0.05, -0.05, 120.0), settings("dual_rate"), priorFor(g));
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
  const AngleLevelGyro g = referenceGyro();
  const CalibrationOutcome o =
      calibrateAngleLevel(g, dualRateProfile(0.4, -0.4, 30.0), settings("dual_rate"), priorFor(g));
  ASSERT_TRUE(o.accepted) << o.reason;
  EXPECT_GE(o.coverage, 0.95);
  EXPECT_LE(testing::peakErrorPpm(o.parameters.scale_factor, g.k), 1.0);
}

TEST(DualRateTest, NonFiniteWaveAnglesAreSkipped) {
  const AngleLevelGyro g = referenceGyro();
  CalibrationSession session(settings("dual_rate"), priorFor(g));
  long i = 0;
  testing::runAngleLevel(g, dualRateProfile(0.05, -0.05, 120.0),
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
  const AngleLevelGyro g = referenceGyro();
  const CalibrationOutcome o =
      calibrateAngleLevel(g, dualRateProfile(0.05, 0.15, 120.0), settings("dual_rate"), priorFor(g));
  ASSERT_TRUE(o.accepted) << o.reason;
  EXPECT_NEAR(o.scale_factor[0].cos[1], 2e-3, 1e-7);
  EXPECT_NEAR(o.drift[0].cos[0], 2e-5, 1e-8);
}

TEST(DualRateTest, StandardErrorsDescribeTheActualErrors) {
  // With white angle noise, (estimate - truth) / std over the harmonics behaves like N(0, 1).
  double z2 = 0.0;
  int n = 0;
  for (std::uint64_t seed = 1; seed <= 4; ++seed) {
    AngleLevelGyro g = referenceGyro();
    g.noise = 1.1e-5;
    g.seed = seed;
    const CalibrationOutcome o =
        calibrateAngleLevel(g, dualRateProfile(0.05, -0.05, 120.0), settings("dual_rate"), priorFor(g));
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

TEST(ConstantRateTest, DriftHarmonicsLeakIntoKByDkOverOmega) {
  AngleLevelGyro g = referenceGyro();
  TurntableProfile p;
  p.append(30.0, 0.0, 0.0, "rest");
  p.append(0.1, 0.0, 0.5, "ramp");
  p.append(250.0, 0.05, 0.0, "turn");
  p.append(0.1, 0.05, -0.5, "ramp");
  p.append(25.0, 0.0, 0.0, "rest");
  const CalibrationOutcome o = calibrateAngleLevel(g, p, settings("constant_rate"), priorFor(g));
  ASSERT_TRUE(o.accepted) << o.reason;
  const HarmonicFitResult& k = o.scale_factor[0];
  const double omega = 0.05 + g.earth_rate;
  // the method's known weakness: D_k / Omega leaks into the harmonics (2e-5 / 0.05 = 4e-4 here)...
  EXPECT_NEAR(k.cos[0], -6e-4 + 2e-5 / omega, 1e-7);
  EXPECT_NEAR(k.sin[0], 4e-4 - 1e-5 / omega, 1e-7);
  // ... and is unbiased where D has no harmonic, once the Earth rate is scaled by K.
  EXPECT_NEAR(k.cos[1], 2e-3, 1e-7);
  // K0 is off by (mean drift - drift at the dwell angles) / Omega: here D varies by 2.2e-5 rad/s
  // around its mean, so up to ~4e-4.
  EXPECT_GT(std::abs(k.mean + 0.56), 1e-5);
  EXPECT_LT(std::abs(k.mean + 0.56), 2.3e-5 / 0.05);
  EXPECT_FALSE(o.notes.empty());
}

TEST(StepTest, RecoversKFromStepsAndDFromDwells) {
  AngleLevelGyro g = referenceGyro();
  g.noise = 1.1e-5;
  YAML::Node n =
      YAML::Load("[{type: steps, angle: 0.3490658503988659, rate: 0.17453292519943295, dwell: 15.0, count: 18}]");
  const TurntableProfile p = TurntableProfile::parse(YamlField(n, "profile"), 0.5);
  CalibrationSettings s = settings("step");
  s.bins = 64;
  const CalibrationOutcome o = calibrateAngleLevel(g, p, s, priorFor(g));
  ASSERT_TRUE(o.accepted) << o.reason << "\n" << emitCalibrationReport(o);
  const HarmonicFitResult& k = o.scale_factor[0];
  EXPECT_NEAR(k.mean, -0.56, 5 * k.mean_std + 1e-7);
  EXPECT_NEAR(k.cos[0], -6e-4, 5 * k.cos_std[0] + 1e-7);
  EXPECT_NEAR(k.sin[0], 4e-4, 5 * k.sin_std[0] + 1e-7);
  EXPECT_NEAR(k.cos[1], 2e-3, 5 * k.cos_std[1] + 1e-7);
  EXPECT_LT(k.cos_std[1], 1e-5);
  EXPECT_NEAR(o.drift[0].mean, 1e-5, 2e-7);
}

TEST(QualityGatesTest, RefuseInsufficientData) {
  const AngleLevelGyro g = referenceGyro();
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
  CalibrationOutcome o = calibrateAngleLevel(g, one, settings("dual_rate"), priorFor(g));
  EXPECT_FALSE(o.accepted);
  EXPECT_TRUE(gateFailed(o, "plateau_groups")) << o.reason;
  // Too short for theta to cover pi.
  o = calibrateAngleLevel(g, dualRateProfile(0.05, -0.05, 40.0), settings("dual_rate"), priorFor(g));
  EXPECT_FALSE(o.accepted);
  EXPECT_TRUE(gateFailed(o, "coverage")) << o.reason;
  EXPECT_NE(o.reason.find("coverage"), std::string::npos);
  // Rates too close.
  o = calibrateAngleLevel(g, dualRateProfile(0.05, 0.055, 130.0), settings("dual_rate"), priorFor(g));
  EXPECT_FALSE(o.accepted);
  EXPECT_TRUE(gateFailed(o, "rate_separation")) << o.reason;
  // A noisy reported rate does not matter where the angle is logged: the logged angle is integrated.
  AngleLevelGyro noisy = g;
  noisy.rate_noise = 1e-4;
  CalibrationSettings loose = settings("dual_rate");
  loose.plateau.rate_tolerance = 1e-3;
  o = calibrateAngleLevel(noisy, dualRateProfile(0.05, -0.05, 120.0), loose, priorFor(g));
  EXPECT_TRUE(o.accepted) << o.reason;
  EXPECT_NEAR(o.scale_factor[0].cos[1], 2e-3, 1e-7);
  // A noisy logged angle does when the logged rate is no cleaner (here its integral wanders more than
  // the angle scatters): the gate judges the table's effect on the K harmonics.
  testing::TableImperfections shaky;
  shaky.encoder_noise = 1e-3;
  AngleLevelGyro rate_noisier = g;
  rate_noisier.rate_noise = 0.01;
  CalibrationSettings smoothed = loose;  // long enough a span that the plateaus are still found
  smoothed.plateau.smoothing_span = 10.0;
  smoothed.gates.max_table_error = 5e-6;  // 1 mrad of encoder noise costs the K harmonics ~10 ppm
  const CalibrationOutcome clean_rate =
      testing::calibrateTableSession(g, shaky, dualRateProfile(0.05, -0.05, 150.0), smoothed, priorFor(g));
  // With the drive's own rate logged, its integral carries the shape and the angle only each
  // plateau's slope: the 1 mrad hardly matters.
  EXPECT_TRUE(clean_rate.accepted) << clean_rate.reason;
  o = testing::calibrateTableSession(rate_noisier, shaky, dualRateProfile(0.05, -0.05, 150.0), smoothed, priorFor(g));
  EXPECT_FALSE(o.accepted);
  EXPECT_TRUE(gateFailed(o, "table_error")) << o.reason;
  for (const auto& gate : o.gates) {
    if (gate.name == "table_error") std::cout << "1 mrad encoder noise: table_error " << gate.value * 1e6 << " ppm\n";
  }
  EXPECT_NE(o.reason.find("table angle errors add"), std::string::npos) << o.reason;
  // Too few samples.
  CalibrationSettings many = settings("dual_rate");
  many.gates.min_samples = 10000000;
  o = calibrateAngleLevel(g, dualRateProfile(0.05, -0.05, 120.0), many, priorFor(g));
  EXPECT_FALSE(o.accepted);
  EXPECT_TRUE(gateFailed(o, "samples"));
}

TEST(CalibrationSessionTest, NoTurntableDataMeansNoCalibration) {
  CalibrationSession session(settings("dual_rate"), GyroParameters());
  // Samples wait up to 60 s for a turntable state, then are dropped (bounded memory).
  for (int i = 0; i < 100000; ++i) session.addWave(toNanoseconds(1.0 + i * 1e-3), 0.2 - 0.028 * i * 1e-3, NAN);
  EXPECT_EQ(session.counters().used, 0u);
  EXPECT_GT(session.counters().unsynchronized, 39000u);
  const CalibrationOutcome o = session.finish();
  EXPECT_FALSE(o.accepted);
}

TEST(CalibrationSessionTest, SynchronisesStreamsArrivingOutOfStep) {
  // The same session with the turntable stream delayed by 300 ms gives the same result.
  const AngleLevelGyro g = referenceGyro();
  const TurntableProfile p = dualRateProfile(0.05, -0.05, 120.0);
  const CalibrationOutcome direct = calibrateAngleLevel(g, p, settings("dual_rate"), priorFor(g));
  CalibrationSession session(settings("dual_rate"), priorFor(g));
  std::deque<std::tuple<Nanoseconds, double, double>> delayed;
  testing::runAngleLevel(g, p, [&](Nanoseconds t, double angle, double rate, double theta) {
    session.addWave(t, theta, NAN);
    delayed.emplace_back(t, angle, rate);
    if (delayed.size() > 300) {
      session.addRotationRecord(std::get<0>(delayed.front()), std::get<1>(delayed.front()),
                                std::get<2>(delayed.front()));
      delayed.pop_front();
    }
  });
  for (const auto& d : delayed) session.addRotationRecord(std::get<0>(d), std::get<1>(d), std::get<2>(d));
  const CalibrationOutcome late = session.finish();
  ASSERT_TRUE(late.accepted) << late.reason;
  EXPECT_EQ(late.samples, direct.samples);
  EXPECT_DOUBLE_EQ(late.scale_factor[0].cos[1], direct.scale_factor[0].cos[1]);
}

TEST(CalibrationSessionTest, AutoFinishWaitsForRestAfterCompleteData) {
  const AngleLevelGyro g = referenceGyro();
  CalibrationSettings s = settings("dual_rate");
  s.auto_finish_idle = 10.0;
  CalibrationSession session(s, priorFor(g));
  double finished_at = -1.0;
  testing::runAngleLevel(g, dualRateProfile(0.05, -0.05, 120.0), [&](Nanoseconds t, double a, double r, double th) {
    session.addRotationRecord(t, a, r);
    session.addWave(t, th, NAN);
    if (finished_at < 0 && session.shouldFinish()) finished_at = toSeconds(t);
  });
  // Plateaus end at ~5 + 0.1 + 120 + 0.2 + 120 + 0.1 = 245.4 s (+ the 1 s stamp offset); then 10 s of rest,
  // found up to half a smoothing span after the table stopped and judged half a span later.
  EXPECT_NEAR(finished_at, 1.0 + 245.4 + 10.0 + s.plateau.smoothing_span, 0.5);
}

}  // namespace
}  // namespace core
}  // namespace hrg_gyro
