// The whole core chain at signal level: simulated gyro with realistic pickoff defects ->
// processor -> dual-rate calibration -> verification against the ground truth, plus the exact
// "injected" model it is compared with and the correction-matrix stage.
#include <gtest/gtest.h>

#include "core/testing/shipped_scenarios.h"
#include "hrg_gyro/core/evaluation/offline_pipeline.h"
#include "hrg_gyro/core/model/parameter_file.h"
#include "hrg_gyro/core/simulation/injected_model.h"

namespace hrg_gyro {
namespace core {
namespace {

using testing::shippedScenario;

std::shared_ptr<const GyroParameters> uncalibrated() {
  return std::make_shared<const GyroParameters>(
      loadParameterFile(std::string(HRG_GYRO_SOURCE_DIR) + "/config/params_uncalibrated.yaml"));
}

TEST(EffectiveModel, WithoutPickoffDefectsIsTheIntrinsicModel) {
  SimulationConfig c = shippedScenario("dual_rate.yaml");
  c.pickoff = PickoffDefects();
  const EffectiveModel e = computeEffectiveModel(c, CorrectionMatrix(), {2, 4}, {2});
  EXPECT_NEAR(e.scale_factor.mean, -0.56, 1e-12);
  EXPECT_NEAR(e.scale_factor.cos[0], -2e-4, 1e-12);
  EXPECT_NEAR(e.scale_factor.sin[0], 1.5e-4, 1e-12);
  EXPECT_NEAR(e.scale_factor.cos[1], 1e-4, 1e-12);
  EXPECT_NEAR(e.drift.cos[0], 2e-5, 1e-15);
}

TEST(EffectiveModel, PickoffDefectsAddTheirFirstOrderSignatures) {
  SimulationConfig c = shippedScenario("dual_rate.yaml");
  c.resonator.scale_factor = HarmonicModel(-0.56);
  const EffectiveModel e = computeEffectiveModel(c, CorrectionMatrix(), {2, 4}, {2});
  const PickoffSignature sig = PickoffArray(c.pickoff).signature();
  const double b = c.resonator.quadrature, f = (1 + b * b) / (1 - b * b), a = 0.05;
  EXPECT_NEAR(e.scale_factor.sin[0] / -0.56, -(sig.dc - sig.ds) * f, 3e-6);
  EXPECT_NEAR(e.scale_factor.cos[0] / -0.56, -(sig.gc - sig.gs) * f, 3e-6);
  EXPECT_NEAR(e.scale_factor.cos[1] / -0.56, -0.75 * a * a, 5e-6);
  EXPECT_GT(e.nonlinearity_ppm, 500.0);
}

TEST(EndToEnd, DualRateCalibrationRemovesTheNonlinearity) {
  // The shipped calibration scenario, shortened verification for test time.
  const SimulationConfig cal = shippedScenario("dual_rate.yaml");
  SimulationConfig ver = shippedScenario("verification.yaml");
  const auto before = uncalibrated();
  CalibrationSettings settings;
  const OfflineCalibration run = calibrateOnSimulation(cal, before, settings);
  ASSERT_TRUE(run.outcome.accepted) << run.outcome.reason;
  EXPECT_EQ(run.processor.rejected(), 0u);

  // Estimated harmonics within a few standard errors of the exact injected ones.
  const EffectiveModel injected =
      computeEffectiveModel(cal, before->correction, settings.scale_factor_orders, settings.drift_orders);
  const HarmonicFitResult& k = run.outcome.scale_factor[0];
  EXPECT_NEAR(k.mean, injected.scale_factor.mean, 4 * k.mean_std);
  for (std::size_t j = 0; j < k.orders.size(); ++j) {
    EXPECT_NEAR(k.cos[j], injected.scale_factor.cos[j], 4 * k.cos_std[j]) << "cos " << k.orders[j];
    EXPECT_NEAR(k.sin[j], injected.scale_factor.sin[j], 4 * k.sin_std[j]) << "sin " << k.orders[j];
  }
  const HarmonicFitResult& d = run.outcome.drift[0];
  EXPECT_NEAR(d.mean, injected.drift.mean, 4 * d.mean_std);
  EXPECT_NEAR(d.cos[0], injected.drift.cos[0], 4 * d.cos_std[0]);

  const auto after = std::make_shared<const GyroParameters>(run.outcome.parameters);
  const auto results = verifyOnSimulation(ver, {before, after});
  ASSERT_TRUE(results[0].ok && results[1].ok) << results[1].reason;
  EXPECT_GT(results[0].nonlinearity_ppm, 3000.0);
  // The measured residual is within the measurement's own noise floor (~2.4 sigma of the peak).
  EXPECT_LT(results[1].nonlinearity_ppm, 2.0);
  EXPECT_LT(results[1].nonlinearity_ppm, 3.5 * results[1].nonlinearity_sigma_ppm + 0.5);
  EXPECT_LT(std::abs(results[1].scale_error_ppm), 2.0);
  EXPECT_LT(results[1].angle_error_max, 1e-2 * results[0].angle_error_max);
}

TEST(EndToEnd, CorrectionMatrixStageRemovesThe2ThetaSignature) {
  const SimulationConfig gen = shippedScenario("generator.yaml");
  const auto before = uncalibrated();
  CalibrationSettings settings;
  settings.method = CalibrationMethodKind::kCorrectionMatrix;
  const OfflineCalibration run = calibrateOnSimulation(gen, before, settings);
  ASSERT_TRUE(run.outcome.accepted) << run.outcome.reason;
  // After P the effective K(theta) keeps only the 4 theta (capacitive) term at first order.
  const SimulationConfig cal = shippedScenario("dual_rate.yaml");
  SimulationConfig no_intrinsic = cal;
  no_intrinsic.resonator.scale_factor = HarmonicModel(-0.56);
  const EffectiveModel raw = computeEffectiveModel(no_intrinsic, CorrectionMatrix(), {2, 4}, {2});
  const EffectiveModel fixed = computeEffectiveModel(no_intrinsic, run.outcome.parameters.correction, {2, 4}, {2});
  EXPECT_GT(std::hypot(raw.scale_factor.cos[0], raw.scale_factor.sin[0]), 5e-4);
  EXPECT_LT(std::hypot(fixed.scale_factor.cos[0], fixed.scale_factor.sin[0]), 2e-6);
  EXPECT_NEAR(fixed.scale_factor.cos[1], raw.scale_factor.cos[1], 2e-6);
  // Harmonics reset for the second stage.
  EXPECT_EQ(run.outcome.parameters.scale_factor.peakDeviation(), 0.0);
}

}  // namespace
}  // namespace core
}  // namespace hrg_gyro
