// The thermal calibration at signal level: the shipped thermal_ramp.yaml session through the
// processor into the thermal and the dual-rate methods (one simulation feeding both, as
// calibrateOnSimulation feeds one), compared with the exact injected model at temperatures across
// the range; then the processor with each model on a verification at the hot end.
#include <gtest/gtest.h>

#include <chrono>

#include "core/testing/angle_level_session.h"
#include "core/testing/model_errors.h"
#include "core/testing/shipped_scenarios.h"
#include "hrg_gyro/core/evaluation/offline_pipeline.h"
#include "hrg_gyro/core/model/parameter_file.h"
#include "hrg_gyro/core/simulation/injected_model.h"

namespace hrg_gyro {
namespace core {
namespace {

using testing::shippedScenario;

/// What a compensation with `estimate` leaves at frequency f against the exact model `truth` of
/// that temperature: peak nonlinearity and scale error, ppm of |K0|.
testing::ModelResidual residualAgainst(const HarmonicModel& estimate, const HarmonicModel& truth, double f) {
  return testing::residualAgainst(estimate, f, truth, NAN, 512);
}

// Node estimates within a few standard errors of the exact injected model at the node's
// temperature (T from the node frequency).
void expectNodesNearTheExactModel(const SimulationConfig& cal, const GyroParameters& prior,
                                  const CalibrationSettings& thermal_settings, const CalibrationOutcome& thermal) {
  const ThermalConfig& t = cal.thermal;
  const double f0 = cal.resonator.frequency;
  for (std::size_t j = 0; j < thermal.frequency_nodes.size(); ++j) {
    const double temperature = t.reference_temperature + (thermal.frequency_nodes[j] - f0) / t.frequency_coefficient;
    const EffectiveModel exact =
        computeEffectiveModel(atTemperature(cal, temperature), prior.correction, thermal_settings.scale_factor_orders,
                              thermal_settings.drift_orders);
    const std::vector<double> k = thermal.scale_factor[j].terms(), k_sd = thermal.scale_factor[j].termStds();
    const std::vector<double> k_true = exact.scale_factor.terms();
    for (std::size_t i = 0; i < k.size(); ++i)
      EXPECT_NEAR(k[i], k_true[i], 4 * k_sd[i]) << "K term " << i << " node " << j;
    const std::vector<double> d = thermal.drift[j].terms(), d_sd = thermal.drift[j].termStds();
    const std::vector<double> d_true = exact.drift.terms();
    for (std::size_t i = 0; i < d.size(); ++i)
      EXPECT_NEAR(d[i], d_true[i], 4 * d_sd[i]) << "D term " << i << " node " << j;
  }
}

TEST(ThermalEndToEnd, RampCalibrationBringsTheResidualBelowOnePpmAcrossTheRange) {
  const auto start = std::chrono::steady_clock::now();
  const SimulationConfig cal = shippedScenario("thermal_ramp.yaml");
  const auto prior = std::make_shared<const GyroParameters>(
      loadParameterFile(std::string(HRG_GYRO_SOURCE_DIR) + "/config/params_uncalibrated.yaml"));
  CalibrationSettings thermal_settings, dual_settings;
  thermal_settings.method = CalibrationMethodKind::kThermal;
  GyroSimulator sim(cal);
  GyroProcessor processor(ProcessorConfig{}, prior);
  CalibrationSession thermal_session(thermal_settings, *prior), dual_session(dual_settings, *prior);
  SimulationSample s;
  while (sim.next(&s)) {
    const ProcessorResult r = processor.process({s.stamp, s.z, s.frequency, s.temperature});
    for (CalibrationSession* session : {&thermal_session, &dual_session}) {
      session->addRotationRecord(s.stamp, s.truth.table_angle, s.truth.table_rate);
      if (r.has_wave) session->addWave(s.stamp, r.wave.theta, s.frequency);
    }
  }
  EXPECT_EQ(processor.counters().rejected(), 0u);
  const CalibrationOutcome thermal = thermal_session.finish(), dual = dual_session.finish();
  ASSERT_TRUE(thermal.accepted) << thermal.reason;
  ASSERT_TRUE(dual.accepted) << dual.reason;
  // Automatic nodes over the frequencies of the plateaus: the soaks at 15 and 35 degC.
  const ThermalConfig& t = cal.thermal;
  const double f0 = cal.resonator.frequency;
  ASSERT_EQ(thermal.frequency_nodes.size(), 3u);
  EXPECT_NEAR(thermal.frequency_nodes.front(), t.frequencyAt(15.0, f0), 1e-9);
  EXPECT_NEAR(thermal.frequency_nodes.back(), t.frequencyAt(35.0, f0), 1e-9);

  expectNodesNearTheExactModel(cal, *prior, thermal_settings, thermal);

  // Across 15..35 degC: the frequency-independent model leaves several ppm, the spline < 1 ppm.
  double thermal_worst = 0.0, dual_worst = 0.0, thermal_scale = 0.0, dual_scale = 0.0;
  for (int i = 0; i <= 8; ++i) {
    const double temperature = 15.0 + 2.5 * i, f = t.frequencyAt(temperature, f0);
    const EffectiveModel exact =
        computeEffectiveModel(atTemperature(cal, temperature), prior->correction, thermal_settings.scale_factor_orders,
                              thermal_settings.drift_orders);
    const HarmonicModel truth = toModel(exact.scale_factor);
    const testing::ModelResidual a = residualAgainst(thermal.parameters.scale_factor, truth, f);
    const testing::ModelResidual b = residualAgainst(dual.parameters.scale_factor, truth, f);
    std::printf(
        "[ measured ] %4.1f degC %.1f Hz: frequency-independent %6.2f ppm (scale %+6.2f), thermal %.3f ppm "
        "(scale %+.3f)\n",
        temperature, f, b.nonlinearity_ppm, b.scale_ppm, a.nonlinearity_ppm, a.scale_ppm);
    thermal_worst = std::max(thermal_worst, a.nonlinearity_ppm);
    dual_worst = std::max(dual_worst, b.nonlinearity_ppm);
    thermal_scale = std::max(thermal_scale, std::abs(a.scale_ppm));
    dual_scale = std::max(dual_scale, std::abs(b.scale_ppm));
  }
  EXPECT_GT(dual_worst, 5.0);
  EXPECT_GT(dual_scale, 5.0);
  EXPECT_LT(thermal_worst, 1.0);
  EXPECT_LT(thermal_scale, 1.0);

  // The processor with each model at the hot end (a 35 degC soak, +-0.08 rad/s): the measured
  // nonlinearity follows, within the verification's own noise floor.
  SimulationConfig ver = cal;
  ver.profile = testing::dualRateProfile(0.08, -0.08, 282.0);
  ver.thermal.profile = TemperatureProfile(35.0);
  ver.seed = 11;
  const auto results = verifyOnSimulation(ver, {std::make_shared<const GyroParameters>(dual.parameters),
                                                std::make_shared<const GyroParameters>(thermal.parameters)});
  ASSERT_TRUE(results[0].ok && results[1].ok) << results[0].reason << results[1].reason;
  std::printf(
      "[ measured ] verification at 35 degC: frequency-independent %.2f +- %.2f ppm, thermal %.2f +- %.2f "
      "ppm; %.1f s wall for the whole test\n",
      results[0].nonlinearity_ppm, results[0].nonlinearity_sigma_ppm, results[1].nonlinearity_ppm,
      results[1].nonlinearity_sigma_ppm,
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  EXPECT_GT(results[0].nonlinearity_ppm, 10.0);
  EXPECT_LT(results[1].nonlinearity_ppm, 3.5 * results[1].nonlinearity_sigma_ppm + 0.5);
}

}  // namespace
}  // namespace core
}  // namespace hrg_gyro
