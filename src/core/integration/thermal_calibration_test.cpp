// The thermal calibration method (K and D as splines over the resonator frequency) on fast
// angle-level sessions: recovery of a frequency-dependent truth, honest standard errors, what a
// frequency-independent model leaves, the gates and the settings.
#include <gtest/gtest.h>

#include "core/testing/angle_level_session.h"
#include "core/testing/model_errors.h"
#include "hrg_gyro/core/calibration/thermal_method.h"
#include "hrg_gyro/core/model/earth_rate.h"
#include "hrg_gyro/core/model/parameter_file.h"

namespace hrg_gyro {
namespace core {
namespace {

using testing::AngleLevelGyro;
using testing::calibrateAngleLevel;
using testing::referencePrior;

constexpr double kF0 = 5000.0;

/// value(f) = v0 + slope (f - 5000), as a two-node linear model over [4990, 5010] Hz.
Eigen::MatrixXd linearNodes(const std::vector<double>& v0, const std::vector<double>& slope) {
  Eigen::MatrixXd m(v0.size(), 2);
  for (std::size_t t = 0; t < v0.size(); ++t) {
    m(t, 0) = v0[t] - 10.0 * slope[t];
    m(t, 1) = v0[t] + 10.0 * slope[t];
  }
  return m;
}

/// The reference magnitudes of the calibration-method tests (docs/math.md, 'Calibration methods'),
/// each coefficient moving with the frequency:
/// over the +-4 Hz of the ramp the K terms move by 4..14 ppm of K0 and D0 by 20 %.
AngleLevelGyro thermalGyro(double f_start, double f_end, double duration) {
  AngleLevelGyro g;
  const FrequencyInterpolator linear({4990.0, 5010.0}, Interpolation::kPiecewiseLinear);
  // Terms: mean, cos 2, cos 4, sin 2, sin 4.
  g.k =
      HarmonicModel({2, 4}, linear, linearNodes({-0.56, -6e-4, 2e-3, 4e-4, 0.0}, {-2e-6, 1e-6, 1.5e-6, -0.5e-6, 0.0}));
  g.d = HarmonicModel({2}, linear, linearNodes({1e-5, 2e-5, -1e-5}, {5e-7, -3e-7, 0.0}));
  g.earth_rate = verticalEarthRate(0.9);
  g.rate_hz = 200.0;
  g.frequency = [=](double t) { return f_start + (f_end - f_start) * t / duration; };
  return g;
}

CalibrationSettings thermalSettings() {
  CalibrationSettings s;
  s.method = CalibrationMethodKind::kThermal;
  s.scale_factor_orders = {2, 4};
  s.drift_orders = {2};
  return s;
}

/// Peak over theta of |K_est - K_true - (K0_est - K0_true)| / |K0_true| at frequency f, ppm: the
/// nonlinearity a compensation with K_est leaves.
double residualNonlinearityPpm(const HarmonicModel& estimate, const HarmonicModel& truth, double f) {
  return testing::residualAgainst(estimate, f, truth, f, 512).nonlinearity_ppm;
}

double scaleErrorPpm(const HarmonicModel& estimate, const HarmonicModel& truth, double f) {
  return testing::residualAgainst(estimate, f, truth, f, 512).scale_ppm;
}

// Plateaus of dual_rate.yaml (4 pairs at +-0.05 rad/s) while the frequency ramps 4996 -> 5004 Hz.
const TurntableProfile kRampProfile = testing::dualRateProfile(0.05, -0.05, 226.0, 4);

TEST(Thermal, RecoversFrequencyDependentKAndDAcrossARamp) {
  const AngleLevelGyro g = thermalGyro(4996.0, 5004.0, kRampProfile.duration());
  const CalibrationOutcome o = calibrateAngleLevel(g, kRampProfile, thermalSettings(), referencePrior());
  ASSERT_TRUE(o.accepted) << o.reason << "\n" << emitCalibrationReport(o);
  // Automatic nodes: 3 by default, evenly over the frequencies seen.
  ASSERT_EQ(o.frequency_nodes.size(), 3u);
  EXPECT_NEAR(o.frequency_nodes.front(), 4996.0, 0.15);  // the first and last settled plateau samples
  EXPECT_NEAR(o.frequency_nodes.back(), 5004.0, 0.15);
  ASSERT_EQ(o.scale_factor.size(), 3u);
  ASSERT_EQ(o.drift.size(), 3u);
  const HarmonicModel& k = o.parameters.scale_factor;
  const HarmonicModel& d = o.parameters.drift;
  EXPECT_TRUE(k.frequencyDependent());
  EXPECT_EQ(k.interpolator().nodes(), o.frequency_nodes);
  EXPECT_EQ(o.parameters.calibration.method, ParameterOrigin::calibratedBy(CalibrationMethodKind::kThermal));
  for (std::size_t j = 0; j < 3; ++j) {
    const double f = o.frequency_nodes[j];
    std::vector<double> truth_k(g.k.termCount()), truth_d(g.d.termCount());
    g.k.coefficientsAt(f, truth_k.data());
    g.d.coefficientsAt(f, truth_d.data());
    const std::vector<double> est_k = o.scale_factor[j].terms(), est_d = o.drift[j].terms();
    for (std::size_t t = 0; t < est_k.size(); ++t)
      EXPECT_NEAR(est_k[t], truth_k[t], 1e-7) << "K term " << t << " node " << j;
    for (std::size_t t = 0; t < est_d.size(); ++t)
      EXPECT_NEAR(est_d[t], truth_d[t], 1e-9) << "D term " << t << " node " << j;
  }
  // Across the calibrated range the frequency-dependent model leaves < 0.2 ppm (no noise here; the
  // dual-rate method itself errs by ~5e-8 in K0 on this profile). Outside the nodes the processor
  // holds the end values and flags the samples.
  for (int i = 0; i <= 8; ++i) {
    const double f = o.frequency_nodes.front() + (o.frequency_nodes.back() - o.frequency_nodes.front()) * i / 8.0;
    EXPECT_LT(residualNonlinearityPpm(k, g.k, f), 0.2) << f;
    EXPECT_LT(std::abs(scaleErrorPpm(k, g.k, f)), 0.2) << f;
    for (double theta : {0.0, 0.4, 1.1, 2.5}) EXPECT_NEAR(d(theta, f), g.d(theta, f), 1e-9) << f << " " << theta;
  }
  EXPECT_GT(o.coverage, 0.95);
  EXPECT_FALSE(o.binned.empty());
  EXPECT_GT(o.nonlinearity_ppm, 4000.0);  // the injected 2e-3 cos 4 theta and 7e-4 in 2 theta
}

TEST(Thermal, AFrequencyIndependentModelLeavesPpmThatTheSplineRemoves) {
  // The same ramp with realistic angle noise (the default pickoff noise at 200 Hz).
  AngleLevelGyro g = thermalGyro(4996.0, 5004.0, kRampProfile.duration());
  g.noise = 4.9e-6;
  CalibrationSettings dual = thermalSettings();
  dual.method = CalibrationMethodKind::kDualRate;
  CalibrationSession thermal_session(thermalSettings(), referencePrior()), dual_session(dual, referencePrior());
  testing::runAngleLevel(g, kRampProfile, [&](Nanoseconds t, double angle, double rate, double theta, double f) {
    for (CalibrationSession* s : {&thermal_session, &dual_session}) {
      s->addRotationRecord(t, angle, rate);
      s->addWave(t, theta, f);
    }
  });
  const CalibrationOutcome thermal = thermal_session.finish(), fixed = dual_session.finish();
  ASSERT_TRUE(thermal.accepted) << thermal.reason;
  ASSERT_TRUE(fixed.accepted) << fixed.reason;
  double worst_fixed = 0.0, worst_thermal = 0.0, worst_fixed_scale = 0.0, worst_thermal_scale = 0.0;
  const std::vector<double>& nodes = thermal.frequency_nodes;
  for (int i = 0; i <= 16; ++i) {
    const double f = nodes.front() + (nodes.back() - nodes.front()) * i / 16.0;
    worst_fixed = std::max(worst_fixed, residualNonlinearityPpm(fixed.parameters.scale_factor, g.k, f));
    worst_thermal = std::max(worst_thermal, residualNonlinearityPpm(thermal.parameters.scale_factor, g.k, f));
    worst_fixed_scale = std::max(worst_fixed_scale, std::abs(scaleErrorPpm(fixed.parameters.scale_factor, g.k, f)));
    worst_thermal_scale =
        std::max(worst_thermal_scale, std::abs(scaleErrorPpm(thermal.parameters.scale_factor, g.k, f)));
  }
  std::printf(
      "[ measured ] over %.2f..%.2f Hz, worst residual nonlinearity and scale error: frequency-independent "
      "%.2f ppm, %.2f ppm; thermal %.3f ppm, %.3f ppm\n",
      nodes.front(), nodes.back(), worst_fixed, worst_fixed_scale, worst_thermal, worst_thermal_scale);
  EXPECT_GT(worst_fixed, 5.0);
  EXPECT_GT(worst_fixed_scale, 5.0);
  EXPECT_LT(worst_thermal, 1.0);
  EXPECT_LT(worst_thermal_scale, 1.0);
}

TEST(Thermal, StandardErrorsDescribeTheActualErrors) {
  // The scatter of every K node value over noise seeds, about the noise-free estimate, is what
  // its standard error says. (About, not against the truth: on this profile the dual-rate estimate
  // itself carries deterministic errors of up to 5e-8 in K0 and 1.5e-8 in the 2 theta terms --
  // the dual_rate method noise free errs by the same -- comparable to the standard errors here.)
  const AngleLevelGyro clean = thermalGyro(4996.0, 5004.0, kRampProfile.duration());
  const CalibrationOutcome reference = calibrateAngleLevel(clean, kRampProfile, thermalSettings(), referencePrior());
  ASSERT_TRUE(reference.accepted) << reference.reason;
  double z2 = 0.0;
  int n = 0;
  for (std::uint64_t seed = 1; seed <= 4; ++seed) {
    AngleLevelGyro g = clean;
    g.noise = 4.9e-6;
    g.seed = seed;
    const CalibrationOutcome o = calibrateAngleLevel(g, kRampProfile, thermalSettings(), referencePrior());
    ASSERT_TRUE(o.accepted) << o.reason;
    ASSERT_EQ(o.frequency_nodes, reference.frequency_nodes);
    for (std::size_t j = 0; j < o.frequency_nodes.size(); ++j) {
      const std::vector<double> est = o.scale_factor[j].terms(), sd = o.scale_factor[j].termStds();
      const std::vector<double> noise_free = reference.scale_factor[j].terms();
      for (std::size_t t = 0; t < est.size(); ++t) {
        ASSERT_GT(sd[t], 0.0);
        z2 += std::pow((est[t] - noise_free[t]) / sd[t], 2);
        ++n;
      }
    }
  }
  std::printf("[ measured ] mean squared z-score of the K node values: %.2f over %d\n", z2 / n, n);
  // 60 squared z-scores (correlated between neighbouring nodes): mean 1 if the errors are honest.
  EXPECT_GT(z2 / n, 0.3);
  EXPECT_LT(z2 / n, 2.0);
}

TEST(Thermal, ExplicitNodesAndTheirRange) {
  const AngleLevelGyro g = thermalGyro(4996.0, 5004.0, kRampProfile.duration());
  CalibrationSettings s = thermalSettings();
  s.thermal.frequency_nodes = {4997.0, 5000.0, 5003.0};
  s.thermal.interpolation = Interpolation::kPiecewiseLinear;
  const CalibrationOutcome o = calibrateAngleLevel(g, kRampProfile, s, referencePrior());
  ASSERT_TRUE(o.accepted) << o.reason;
  EXPECT_EQ(o.frequency_nodes, s.thermal.frequency_nodes);
  EXPECT_EQ(o.parameters.scale_factor.interpolator().kind(), Interpolation::kPiecewiseLinear);
  // The quarter of the ramp outside [4997, 5003] Hz is left out, and said so.
  bool noted = false;
  for (const std::string& note : o.notes)
    noted = noted || note.find("outside the frequency nodes") != std::string::npos;
  EXPECT_TRUE(noted);
  std::vector<double> truth(g.k.termCount());
  g.k.coefficientsAt(5000.0, truth.data());
  EXPECT_NEAR(o.scale_factor[1].cos[1], truth[2], 1e-7);
  // The written file reads back to the same model (frequency_nodes in the parameter schema).
  const GyroParameters back = parseParameterText(emitParameters(o.parameters));
  EXPECT_TRUE(back.scale_factor == o.parameters.scale_factor);
  EXPECT_TRUE(back.drift == o.parameters.drift);
}

TEST(Thermal, RefusesWithoutFrequencyOrCoverage) {
  // No frequency on the samples: nothing to fit against.
  AngleLevelGyro g = thermalGyro(4996.0, 5004.0, kRampProfile.duration());
  g.frequency = nullptr;
  g.k = HarmonicModel({2}, -0.56, {1e-4}, {0.0});
  g.d = HarmonicModel(1e-5);
  CalibrationOutcome o =
      calibrateAngleLevel(g, testing::dualRateProfile(0.05, -0.05, 120.0), thermalSettings(), referencePrior());
  EXPECT_FALSE(o.accepted);
  EXPECT_NE(o.reason.find("samples"), std::string::npos) << o.reason;
  // A constant frequency spans no range.
  g.frequency = [](double) { return kF0; };
  o = calibrateAngleLevel(g, testing::dualRateProfile(0.05, -0.05, 120.0), thermalSettings(), referencePrior());
  EXPECT_FALSE(o.accepted);
  EXPECT_NE(o.reason.find("frequency_nodes"), std::string::npos) << o.reason;
  // Too many nodes for one pair of plateaus across the ramp: some node interval misses theta at
  // one of the rates.
  g.frequency = [](double t) { return 4996.0 + 8.0 * t / 250.0; };
  CalibrationSettings s = thermalSettings();
  s.thermal.node_count = 6;
  o = calibrateAngleLevel(g, testing::dualRateProfile(0.05, -0.05, 120.0), s, referencePrior());
  EXPECT_FALSE(o.accepted);
  EXPECT_NE(o.reason.find("coverage"), std::string::npos) << o.reason;
}

TEST(Thermal, ProgressAndCompletionFollowTheNodeIntervals) {
  const AngleLevelGyro g = thermalGyro(4996.0, 5004.0, kRampProfile.duration());
  CalibrationSettings s = thermalSettings();
  s.thermal.frequency_nodes = {4996.0, 5000.0, 5004.0};
  CalibrationSession session(s, referencePrior());
  double complete_at = -1.0;
  testing::runAngleLevel(g, kRampProfile, [&](Nanoseconds t, double angle, double rate, double theta, double f) {
    session.addRotationRecord(t, angle, rate);
    session.addWave(t, theta, f);
    if (complete_at < 0.0 && session.complete()) complete_at = toSeconds(t);
  });
  // Complete only once the upper interval (second half of the ramp) has both rates over theta.
  EXPECT_GT(complete_at, 0.5 * kRampProfile.duration());
  EXPECT_NE(session.progress().summary.find("thermal"), std::string::npos);
  EXPECT_TRUE(session.finish().accepted);
}

TEST(Thermal, SettingsNameBadKeys) {
  auto expectError = [](const std::string& yaml, const std::string& key) {
    try {
      CalibrationSettings::parse(YamlField(YAML::Load(yaml), ""));
      ADD_FAILURE() << yaml;
    } catch (const ConfigError& e) {
      EXPECT_EQ(e.key(), key) << e.what();
    }
  };
  expectError("thermal: {nodes: 4}", "thermal.nodes");
  expectError("thermal: {frequency_nodes: [5000]}", "thermal.frequency_nodes");
  expectError("thermal: {frequency_nodes: [5000, 4990]}", "thermal.frequency_nodes[1]");
  expectError("thermal: {node_count: 1}", "thermal.node_count");
  expectError("thermal: {interpolation: akima}", "thermal.interpolation");
  expectError("thermal: {slice_width: 0}", "thermal.slice_width");
  expectError("method: thermals", "method");
  const CalibrationSettings s = CalibrationSettings::parse(YamlField(
      YAML::Load("{method: thermal, thermal: {frequency_nodes: [4990, 5000, 5010], interpolation: piecewise_linear,"
                 " slice_width: 0.25, max_slices: 64}}"),
      ""));
  EXPECT_EQ(s.method, CalibrationMethodKind::kThermal);
  EXPECT_EQ(s.thermal.frequency_nodes, (std::vector<double>{4990, 5000, 5010}));
  EXPECT_EQ(s.thermal.interpolation, Interpolation::kPiecewiseLinear);
  EXPECT_EQ(s.thermal.slice_width, 0.25);
  EXPECT_EQ(s.thermal.max_slices, 64);
  EXPECT_EQ(findCalibrationMethod("thermal"), CalibrationMethodKind::kThermal);
}

}  // namespace
}  // namespace core
}  // namespace hrg_gyro
