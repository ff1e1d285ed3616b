// The simulator's temperature: profiles, the thermal scenario section, and the gyro it simulates
// at each temperature.
#include <gtest/gtest.h>

#include "core/testing/shipped_scenarios.h"
#include "core/testing/simulator_pairs.h"
#include "hrg_gyro/core/simulation/gyro_simulator.h"

namespace hrg_gyro {
namespace core {
namespace {

YamlField parse(const std::string& text) { return YamlField(YAML::Load(text), ""); }

using testing::shippedScenario;

template <typename F>
void expectConfigError(F&& f, const std::string& key) {
  try {
    f();
    ADD_FAILURE() << "no error, expected one naming " << key;
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.key(), key) << e.what();
  }
}

TEST(TemperatureProfile, HoldRampAndLaggedStep) {
  const TemperatureProfile p = TemperatureProfile::parse(
      parse("p: [{type: hold, duration: 10}, {type: ramp, to: 30, duration: 100}, {type: ramp, to: 25, rate: 0.5},"
            " {type: step, to: 15, duration: 50, time_constant: 10}, {type: step, to: 40, duration: 5}]")["p"],
      20.0);
  EXPECT_EQ(p.evaluate(-1.0), 20.0);
  EXPECT_EQ(p.evaluate(5.0), 20.0);
  EXPECT_NEAR(p.evaluate(60.0), 25.0, 1e-12);                                  // half way up the ramp
  EXPECT_NEAR(p.evaluate(110.0), 30.0, 1e-12);                                 // its end
  EXPECT_NEAR(p.evaluate(115.0), 27.5, 1e-12);                                 // 0.5 degC/s down: 10 s to 25
  EXPECT_NEAR(p.evaluate(120.0 + 10.0), 15.0 + 10.0 * std::exp(-1.0), 1e-12);  // one time constant
  EXPECT_NEAR(p.evaluate(170.0 + 1e-9), 40.0, 1e-12);                          // an instant step
  EXPECT_EQ(p.evaluate(1e6), 40.0);                                            // held after the end
  EXPECT_NEAR(p.duration(), 175.0, 1e-12);
  EXPECT_EQ(p.minimum(), 15.0 + 10.0 * std::exp(-5.0));
  EXPECT_EQ(p.maximum(), 40.0);
}

TEST(TemperatureProfile, BadSegmentsNameTheirKey) {
  auto check = [](const std::string& yaml, const std::string& key) {
    expectConfigError([&] { TemperatureProfile::parse(parse(yaml)["p"], 20.0); }, key);
  };
  check("p: []", "p");
  check("p: [{type: bake, duration: 1}]", "p[0].type");
  check("p: [{type: hold}]", "p[0].duration");
  check("p: [{type: hold, duration: 0}]", "p[0].duration");
  check("p: [{type: ramp, to: 30}]", "p[0]");  // neither duration nor rate
  check("p: [{type: ramp, to: 30, duration: 5, rate: 1}]", "p[0]");
  check("p: [{type: ramp, to: 300, duration: 5}]", "p[0].to");
  check("p: [{type: ramp, to: 20, rate: 1}]", "p[0].to");  // already there
  check("p: [{type: step, to: 30, duration: 5, time_constant: -1}]", "p[0].time_constant");
  check("p: [{type: hold, duration: 5, length: 2}]", "p[0].length");
}

const std::string kProfile = "turntable: {profile: [{type: rate, rate: 0.1, duration: 2}]}\n";

TEST(ThermalScenario, BadKeysAreNamed) {
  auto check = [](const std::string& yaml, const std::string& key) {
    expectConfigError([&] { SimulationConfig::parse(parse(yaml + kProfile)); }, key);
  };
  check("thermal: {reference_temp: 25}\n", "thermal.reference_temp");
  check("thermal: {frequency_coefficient: 400}\n", "thermal.frequency_coefficient");
  check("thermal: {profile: [{type: hold}]}\n", "thermal.profile[0].duration");
  check("thermal: {coefficients: {gain: [0, 0]}}\n", "thermal.coefficients.gain");
  check("thermal: {coefficients: {gain_error: [0, 0, 0]}}\n", "thermal.coefficients.gain_error");
  check("thermal: {coefficients: {misplacement: [0, 0, 0, 0, 0, 0, 0, 0.1]}}\n",
        "thermal.coefficients.misplacement[7]");
  check("thermal: {coefficients: {scale_factor: {orders: [3], mean: 0, cos: [0], sin: [0]}}}\n",
        "thermal.coefficients.scale_factor.orders[0]");
  // Limits that only the whole gyro can check, at the extremes of the profile.
  check("thermal: {frequency_coefficient: -60, profile: [{type: ramp, to: 120, duration: 10}]}\n",
        "thermal.frequency_coefficient");
  check("thermal: {coefficients: {amplitude: -0.006}, profile: [{type: ramp, to: 190, duration: 10}]}\n",
        "thermal.coefficients.amplitude");
  check(
      "pickoff: {gain_error: [0, 0, 0, 0, 0, 0.45, 0, 0]}\n"
      "thermal: {coefficients: {gain_error: [0, 0, 0, 0, 0, 0.0009, 0, 0]}, "
      "profile: [{type: ramp, to: 150, duration: 10}]}\n",
      "thermal.coefficients.gain_error[5]");
  check(
      "thermal: {coefficients: {scale_factor: {orders: [], mean: 0.01, cos: [], sin: []}},"
      " profile: [{type: ramp, to: 90, duration: 10}]}\n",
      "thermal.coefficients.scale_factor");
}

TEST(ThermalScenario, ShippedRampReportsTemperatureAndFrequency) {
  const SimulationConfig c = shippedScenario("thermal_ramp.yaml");
  ASSERT_TRUE(c.thermal.enabled);
  EXPECT_EQ(c.thermal.profile.minimum(), 15.0);
  EXPECT_EQ(c.thermal.profile.maximum(), 35.0);
  // Its dual-rate plateaus lie inside the ramp, so every calibration sample has its own temperature.
  EXPECT_NEAR(c.thermal.profile.duration(), c.profile.duration(), 0.5);
}

// Without a thermal section nothing changes (bags stay bit-identical); a thermal section that
// changes nothing gives the same signal, now with a temperature.
TEST(ThermalSimulation, NeutralThermalSectionLeavesTheSignalBitIdentical) {
  const SimulationConfig plain = SimulationConfig::parse(parse(
      "pickoff: {misplacement: [1e-3, 0, 0, 0, 0, 0, 0, -1e-3], amplitude_to_gap: 0.05, noise: 2e-4}\n" + kProfile));
  SimulationConfig neutral = plain;
  neutral.thermal.enabled = true;
  neutral.thermal.reference_temperature = 21.0;
  neutral.thermal.profile = TemperatureProfile(21.0);
  neutral.thermal.frequency_coefficient = 0.4;
  GyroSimulator a(plain), b(neutral);
  const int n = testing::stepTogether(&a, &b, [](const SimulationSample& sa, const SimulationSample& sb, int) {
    EXPECT_TRUE(std::isnan(sa.temperature) && std::isnan(sa.truth.temperature));
    EXPECT_EQ(sb.temperature, 21.0);
    EXPECT_EQ(sb.truth.temperature, 21.0);
    EXPECT_EQ(sa.frequency, 5000.0);
    EXPECT_EQ(sb.frequency, 5000.0);
  });
  EXPECT_GT(n, 2000);
}

// At a constant temperature the simulator is exactly the gyro frozen at that temperature, which
// is what the exact injected model (computeEffectiveModel of atTemperature) describes.
TEST(ThermalSimulation, AtConstantTemperatureItIsTheFrozenGyro) {
  SimulationConfig hot = shippedScenario("thermal_ramp.yaml");
  hot.profile = TurntableProfile();
  hot.profile.append(0.5, 0.0, 0.5, "spin_up");
  hot.profile.append(3.0, 0.25, 0.0, "turn");
  hot.thermal.profile = TemperatureProfile(40.0);
  const SimulationConfig frozen = atTemperature(hot, 40.0);
  EXPECT_FALSE(frozen.thermal.enabled);
  EXPECT_DOUBLE_EQ(frozen.resonator.amplitude, 1.0 - 2e-4 * 15.0);
  EXPECT_DOUBLE_EQ(frozen.pickoff.gain_error[0], 2.1e-3 + 3e-6 * 15.0);
  EXPECT_DOUBLE_EQ(frozen.pickoff.misplacement[7], -1.2e-3 - 2e-7 * 15.0);
  EXPECT_DOUBLE_EQ(frozen.pickoff.gap, hot.pickoff.gap);  // the electrode gap does not move
  EXPECT_DOUBLE_EQ(frozen.resonator.scale_factor.meanAt(NAN), -0.56 - 5e-7 * 15.0);
  EXPECT_DOUBLE_EQ(frozen.resonator.scale_factor(0.0), -0.56 - 5e-7 * 15.0 - 2e-4 + 1.5e-7 * 15.0 + 1e-4);
  EXPECT_DOUBLE_EQ(frozen.resonator.drift(0.0), 1e-5 + 2e-7 * 15.0 + 2e-5 + 1e-7 * 15.0);
  GyroSimulator a(hot), b(frozen);
  const int n = testing::stepTogether(&a, &b, [&](const SimulationSample& sa, const SimulationSample&, int) {
    EXPECT_EQ(sa.temperature, 40.0);
    EXPECT_DOUBLE_EQ(sa.frequency, 5000.0 + 0.4 * 15.0);
    EXPECT_DOUBLE_EQ(sa.truth.amplitude, frozen.resonator.amplitude);
  });
  EXPECT_GT(n, 600);
}

// Along a ramp each sample reports the temperature at the centre of its window and f(T).
TEST(ThermalSimulation, RampMovesTheReportedFrequencyAndTheDefects) {
  SimulationConfig c = shippedScenario("thermal_ramp.yaml");
  c.profile = TurntableProfile();
  c.profile.append(4.0, 0.0, 0.0, "rest");
  c.thermal.profile = TemperatureProfile(20.0);
  c.thermal.profile.appendRamp(4.0, 30.0);
  GyroSimulator sim(c);
  SimulationSample s;
  double previous = -INFINITY;
  int n = 0;
  while (sim.next(&s)) {
    const double t_center = toSeconds(s.stamp) - c.start_time;
    EXPECT_NEAR(s.temperature, 20.0 + 2.5 * t_center, 1e-9) << n;
    EXPECT_EQ(s.truth.temperature, s.temperature);
    EXPECT_NEAR(s.frequency, 5000.0 + 0.4 * (s.temperature - 25.0), 1e-9);
    EXPECT_EQ(s.truth.frequency, s.frequency);
    EXPECT_GT(s.temperature, previous);
    previous = s.temperature;
    ++n;
  }
  EXPECT_EQ(n, 800);
}

}  // namespace
}  // namespace core
}  // namespace hrg_gyro
