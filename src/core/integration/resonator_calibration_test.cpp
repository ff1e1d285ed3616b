// A gyro simulated from its equations of motion (config/scenarios/resonator_dual_rate.yaml: the
// averaged resonator with its loops) calibrated on the table like any other: the dual-rate method
// recovers the K(theta) and D(theta) the defects predict (the exact settled drift, seen through the
// pickoffs: computeEffectiveModel) within its reported standard errors.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>

#include "core/testing/angle_level_session.h"
#include "core/testing/model_errors.h"
#include "core/testing/shipped_scenarios.h"
#include "hrg_gyro/core/evaluation/offline_pipeline.h"
#include "hrg_gyro/core/simulation/injected_model.h"

namespace hrg_gyro {
namespace core {
namespace {

using testing::shippedScenario;
using testing::worstNormalisedError;

TEST(ResonatorCalibration, DualRateRecoversTheDriftTheDefectsPredict) {
  SimulationConfig c = shippedScenario("resonator_dual_rate.yaml");
  ASSERT_TRUE(c.dynamics.averaged());
  // The shipped session, shortened for test time: +-0.1 rad/s, one full turn of theta per plateau.
  c.profile = testing::dualRateProfile(0.1, -0.1, 118.0);
  auto prior = std::make_shared<GyroParameters>();
  prior->earth_rate.latitude = c.latitude;
  CalibrationSettings settings;
  settings.plateau.settle_time = 3.0;
  const auto start = std::chrono::steady_clock::now();
  const OfflineCalibration run = calibrateOnSimulation(c, prior, settings);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  ASSERT_TRUE(run.outcome.accepted) << run.outcome.reason;
  const EffectiveModel injected =
      computeEffectiveModel(c, prior->correction, settings.scale_factor_orders, settings.drift_orders);
  const HarmonicFitResult& d = run.outcome.drift[0];
  const HarmonicFitResult& k = run.outcome.scale_factor[0];
  std::printf("[ measured ] %.0f s simulated, calibrated in %.1f s\n", run.simulated_seconds, seconds);
  std::printf(
      "[ measured ] D0 %.4g (injected %.4g, sigma %.2g); D cos2 %.5g (%.5g, %.2g), sin2 %.5g (%.5g, %.2g) rad/s\n",
      d.mean, injected.drift.mean, d.mean_std, d.cos[0], injected.drift.cos[0], d.cos_std[0], d.sin[0],
      injected.drift.sin[0], d.sin_std[0]);
  const double d_error = worstNormalisedError(d, injected.drift),
               k_error = worstNormalisedError(k, injected.scale_factor);
  std::printf("[ measured ] largest |estimate - injected| / sigma: D %.2f, K %.2f\n", d_error, k_error);
  EXPECT_LT(d_error, 3.0);
  EXPECT_LT(k_error, 3.0);
  // The shell's order-2 drift is there and large against its standard error.
  EXPECT_GT(std::hypot(d.cos[0], d.sin[0]), 1e-5);
}

}  // namespace
}  // namespace core
}  // namespace hrg_gyro
