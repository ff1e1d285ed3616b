// Turntable profiles and scenario files.
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include "hrg_gyro/core/common/units.h"
#include "hrg_gyro/core/simulation/simulation_config.h"

namespace hrg_gyro {
namespace core {
namespace {

YamlField parse(const std::string& text) { return YamlField(YAML::Load(text), ""); }

TEST(TurntableProfile, StepsMoveExactlyTheirAngleAndRest) {
  const TurntableProfile p = TurntableProfile::parse(
      parse("profile: [{type: steps, angle: 0.35, rate: 0.17, dwell: 10.0, count: 4}]")["profile"], 0.5);
  double angle, rate;
  p.evaluate(p.duration(), &angle, &rate);
  EXPECT_NEAR(angle, 4 * 0.35, 1e-12);
  EXPECT_EQ(rate, 0.0);
  // Mid-dwell after the second step.
  const std::string* label = nullptr;
  double t = 0.0;
  for (const auto& piece : p.pieces()) {
    if (piece.label == "steps_0/dwell") t = piece.start + 0.5 * piece.duration;
  }
  p.evaluate(t, &angle, &rate, &label);
  EXPECT_EQ(*label, "steps_0/dwell");
  EXPECT_EQ(rate, 0.0);
  const double steps_done = angle / 0.35;
  EXPECT_NEAR(steps_done, std::round(steps_done), 1e-9);
}

TEST(TurntableProfile, RateAndDualRateRampAtTheAccelerationLimit) {
  const TurntableProfile p = TurntableProfile::parse(
      parse("profile: [{type: dual_rate, rates: [0.1, -0.1], duration: 20.0, settle: 1.0, label: cal}]")["profile"],
      0.5);
  // ramp 0.2 s, settle 1, hold 20, ramp 0.4 s, settle 1, hold 20, ramp to 0 0.2 s
  EXPECT_NEAR(p.duration(), 0.2 + 1 + 20 + 0.4 + 1 + 20 + 0.2, 1e-12);
  double angle, rate;
  const std::string* label;
  p.evaluate(10.0, &angle, &rate, &label);
  EXPECT_DOUBLE_EQ(rate, 0.1);
  EXPECT_EQ(*label, "cal/rate1");
  p.evaluate(30.0, &angle, &rate, &label);
  EXPECT_DOUBLE_EQ(rate, -0.1);
  // Angle is the integral of the rate: symmetric profile returns to (almost) zero.
  p.evaluate(p.duration(), &angle, &rate);
  EXPECT_NEAR(angle, 0.0, 1e-12);
}

TEST(TurntableProfile, PiecewiseIsLinearInRate) {
  const TurntableProfile p = TurntableProfile::parse(
      parse("profile: [{type: piecewise, points: [[0, 0.0], [10, 0.2], [20, 0.2]]}]")["profile"], 0.5);
  double angle, rate;
  p.evaluate(5.0, &angle, &rate);
  EXPECT_NEAR(rate, 0.1, 1e-15);
  EXPECT_NEAR(angle, 0.25, 1e-12);  // integral of 0.02 t from 0 to 5
}

TEST(TurntableProfile, BadSegmentsNameTheirKey) {
  auto expectError = [](const std::string& yaml, const std::string& key) {
    try {
      TurntableProfile::parse(parse(yaml)["profile"], 0.5);
      ADD_FAILURE() << yaml;
    } catch (const ConfigError& e) {
      EXPECT_EQ(e.key(), key) << e.what();
    }
  };
  expectError("profile: [{type: spin}]", "profile[0].type");
  expectError("profile: [{type: dwell}]", "profile[0].duration");
  expectError("profile: [{type: rate, rate: 0.1, duration: -1}]", "profile[0].duration");
  expectError("profile: [{type: dual_rate, rates: [0.1, 0.1], duration: 5}]", "profile[0].rates");
  expectError("profile: [{type: piecewise, points: [[1, 0], [2, 1]]}]", "profile[0].points[0]");
  expectError("profile: [{type: dwell, duration: 1, speed: 2}]", "profile[0].speed");
}

std::string readFile(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

TEST(Scenarios, ShippedScenariosParseAndDescribeTheSameGyro) {
  const std::string dir = std::string(HRG_GYRO_SOURCE_DIR) + "/config/scenarios/";
  std::string reference_gyro;
  for (const char* name : {"dual_rate.yaml", "constant_rate.yaml", "steps.yaml", "verification.yaml", "generator.yaml",
                           "demo.yaml", "two_stage.yaml", "thermal_ramp.yaml"}) {
    SCOPED_TRACE(name);
    const SimulationConfig c = SimulationConfig::load(dir + name, nodeOnlyScenarioKeys());
    EXPECT_EQ(c.resonator.samples_per_period, 32);
    EXPECT_DOUBLE_EQ(c.pickoff.gap, 20.0);
    // The gyro block (everything after the seed line up to the session part) is identical.
    const std::string text = readFile(dir + name);
    const std::size_t from = text.find("start_time:"), to = text.find("# ---- The session");
    ASSERT_NE(from, std::string::npos);
    ASSERT_NE(to, std::string::npos);
    const std::string gyro = text.substr(from, to - from);
    if (reference_gyro.empty()) reference_gyro = gyro;
    EXPECT_EQ(gyro, reference_gyro);
  }
}

TEST(Scenarios, RejectsBadValuesByKey) {
  auto expectError = [](const std::string& yaml, const std::string& key) {
    try {
      SimulationConfig::parse(parse(yaml));
      ADD_FAILURE() << yaml;
    } catch (const ConfigError& e) {
      EXPECT_EQ(e.key(), key) << e.what();
    }
  };
  const std::string profile = "turntable: {profile: [{type: dwell, duration: 1}]}\n";
  expectError("resonator: {samples_per_period: 4}\n" + profile, "resonator.samples_per_period");
  expectError("pickoff: {misplacement: [0, 0, 0]}\n" + profile, "pickoff.misplacement");
  expectError("pickoff: {amplitude_to_gap: 0.7}\n" + profile, "pickoff.amplitude_to_gap");
  expectError("resonator: {scale_factor: {orders: [3], mean: -0.5, cos: [0], sin: [0]}}\n" + profile,
              "resonator.scale_factor.orders[0]");
  expectError("seed: 1\n", "turntable.profile");
  expectError("time_scale: 10\n" + profile, "time_scale");  // node-only keys need the node's list
  EXPECT_NO_THROW(SimulationConfig::parse(parse("time_scale: 10\n" + profile), nodeOnlyScenarioKeys()));
}

}  // namespace
}  // namespace core
}  // namespace hrg_gyro
