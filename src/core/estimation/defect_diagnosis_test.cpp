// The root-cause diagnosis against the simulator's injected pickoff defects: first from the exact
// effective model (the formulas), then from a real dual-rate calibration (the formulas plus the
// estimation noise, within the stated uncertainty); and the recommended P removes the 2 theta terms.
#include "hrg_gyro/core/estimation/defect_diagnosis.h"

#include <gtest/gtest.h>

#include "hrg_gyro/core/evaluation/offline_pipeline.h"
#include "hrg_gyro/core/model/parameter_file.h"
#include "hrg_gyro/core/signal/pickoff_array.h"
#include "hrg_gyro/core/simulation/injected_model.h"

namespace hrg_gyro {
namespace core {
namespace {

// The worked example of docs/calibration.md ('Reading the root-cause diagnosis'): dual_rate.yaml
// with an isotropic resonator, pickoff defects only.
SimulationConfig pickoffOnlyScenario() {
  SimulationConfig c = SimulationConfig::load(std::string(HRG_GYRO_SOURCE_DIR) + "/config/scenarios/diagnosis.yaml",
                                              nodeOnlyScenarioKeys());
  EXPECT_TRUE(c.resonator.scale_factor.orders().empty());
  return c;
}

void expectRecovers(const DefectDiagnosis& d, const SimulationConfig& c, double sigmas) {
  const PickoffSignature s = PickoffArray(c.pickoff).signature();
  ASSERT_TRUE(d.valid) << d.note;
  EXPECT_NEAR(d.gain_mismatch, s.gc - s.gs, sigmas * d.gain_mismatch_std);
  EXPECT_NEAR(d.misplacement_difference, s.dc - s.ds, sigmas * d.misplacement_difference_std);
  const double a = c.resonator.amplitude / c.pickoff.gap;  // A/d0
  EXPECT_NEAR(d.pickoff_ratio, a, sigmas * d.pickoff_ratio_std);
  // The uncertainties are informative: well below the values themselves.
  EXPECT_LT(d.gain_mismatch_std, 0.1 * std::abs(s.gc - s.gs));
  EXPECT_LT(d.misplacement_difference_std, 0.1 * std::abs(s.dc - s.ds));
  EXPECT_LT(d.pickoff_ratio_std, 0.1 * a);
}

TEST(DefectDiagnosisTest, ReadsTheInjectedDefectsFromTheExactModel) {
  const SimulationConfig c = pickoffOnlyScenario();
  const EffectiveModel e = computeEffectiveModel(c, CorrectionMatrix(), {2, 4}, {2});
  const double q = c.resonator.quadrature / c.resonator.amplitude;
  const DefectDiagnosis d = diagnoseDefects(e.scale_factor, q, CorrectionMatrix());
  expectRecovers(d, c, 1.0);
}

TEST(DefectDiagnosisTest, RecommendedCorrectionCancelsTheTwoThetaTerms) {
  const SimulationConfig c = pickoffOnlyScenario();
  const EffectiveModel before = computeEffectiveModel(c, CorrectionMatrix(), {2, 4}, {2});
  const double q = c.resonator.quadrature / c.resonator.amplitude;
  const DefectDiagnosis d = diagnoseDefects(before.scale_factor, q, CorrectionMatrix());
  const EffectiveModel after = computeEffectiveModel(c, d.recommended_correction, {2, 4}, {2});
  const double before2 = std::hypot(before.scale_factor.cos[0], before.scale_factor.sin[0]);
  const double after2 = std::hypot(after.scale_factor.cos[0], after.scale_factor.sin[0]);
  EXPECT_LT(after2, 0.02 * before2) << before2 << " -> " << after2;
  // The 4 theta term is the pickoff nonlinearity: P does not touch it.
  EXPECT_NEAR(after.scale_factor.cos[1], before.scale_factor.cos[1], 0.02 * std::abs(before.scale_factor.cos[1]));
  // Starting from that P, the diagnosis finds (almost) nothing left and keeps recommending it.
  const DefectDiagnosis again = diagnoseDefects(after.scale_factor, q, d.recommended_correction);
  for (int i = 0; i < 4; ++i) {
    EXPECT_NEAR(again.recommended_correction.p[i], d.recommended_correction.p[i],
                0.02 * std::abs(d.recommended_correction.p[i]) + 1e-6);
  }
}

TEST(DefectDiagnosisTest, ReadsTheInjectedDefectsFromADualRateCalibration) {
  const SimulationConfig c = pickoffOnlyScenario();
  const auto params = std::make_shared<const GyroParameters>(
      loadParameterFile(std::string(HRG_GYRO_SOURCE_DIR) + "/config/params_uncalibrated.yaml"));
  const OfflineCalibration run = calibrateOnSimulation(c, params, CalibrationSettings());
  ASSERT_TRUE(run.outcome.accepted) << run.outcome.reason;
  const DefectDiagnosis d =
      diagnoseDefects(run.outcome.scale_factor[0], run.outcome.quadrature_ratio, params->correction);
  expectRecovers(d, c, 3.0);
}

TEST(DefectDiagnosisTest, IncompleteFitsAreReportedNotGuessed) {
  HarmonicFitResult k;
  k.ok = true;
  k.orders = {2};
  k.mean = -0.56;
  k.cos = {1e-3};
  k.sin = {0.0};
  k.cos_std = k.sin_std = {1e-6};
  DefectDiagnosis d = diagnoseDefects(k, 0.0, CorrectionMatrix());
  EXPECT_FALSE(d.valid);
  EXPECT_NE(d.note.find("4 theta"), std::string::npos);
  EXPECT_NEAR(d.gain_mismatch, 1e-3 / 0.56, 1e-12);
  k.ok = false;
  d = diagnoseDefects(k, 0.0, CorrectionMatrix());
  EXPECT_FALSE(d.valid);
  EXPECT_EQ(d.recommended_correction, CorrectionMatrix());
}

TEST(DefectDiagnosisTest, DescriptionCarriesEveryQuantity) {
  DefectDiagnosis d;
  d.gain_mismatch = 3.5e-4;
  d.gain_mismatch_std = 3.6e-6;
  d.misplacement_difference = 1.1e-3;
  d.pickoff_ratio = 0.05;
  d.recommended_correction.p = {1.75e-4, -1.75e-4, 5.5e-4, -5.5e-4};
  d.frequency = NAN;
  const std::string text = describe(d);
  for (const char* part : {"gc - gs", "+3.500e-04 +- 3.6e-06", "dc - ds", "+1.100e-03", "A/d0", "0.0500",
                           "recommended P = [+1.750e-04, -1.750e-04, +5.500e-04, -5.500e-04]"}) {
    EXPECT_NE(text.find(part), std::string::npos) << part << "\n" << text;
  }
}

TEST(DefectDiagnosisTest, QuadratureFactor) {
  EXPECT_DOUBLE_EQ(quadratureFactor(0.0), 1.0);
  EXPECT_NEAR(quadratureFactor(0.02), (1 + 4e-4) / (1 - 4e-4), 1e-15);
  EXPECT_DOUBLE_EQ(quadratureFactor(NAN), 1.0);
  EXPECT_DOUBLE_EQ(quadratureFactor(2.0), 1.0);  // not a standing wave: no factor
}

}  // namespace
}  // namespace core
}  // namespace hrg_gyro
