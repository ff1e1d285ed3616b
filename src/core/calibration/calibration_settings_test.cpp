// The calibrator settings as the node and `hrg_bag calibrate --config` read them: the defaults, and
// every bad value refused with the key named.
#include "hrg_gyro/core/calibration/calibration_settings.h"

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "core/testing/refusal.h"

namespace hrg_gyro {
namespace core {
namespace {

CalibrationSettings parse(const std::string& yaml) {
  return CalibrationSettings::parse(YamlField(YAML::Load(yaml), ""));
}

/// The key a refusal names ("accepted" when nothing is refused).
std::string keyOf(const std::string& yaml) {
  return refusedKey([&] { parse(yaml); });
}

/// Each settings text and the key it is refused by ("accepted": none).
void expectRefused(const std::vector<RefusalCase>& cases) {
  expectRefusedKeys([](const std::string& yaml) { parse(yaml); }, cases);
}

TEST(CalibrationSettingsTest, TheBiasTrendIsLinearByDefaultAndItsKeysAreChecked) {
  const CalibrationSettings d = parse("{}");
  EXPECT_EQ(d.bias_trend_order, 1);
  EXPECT_DOUBLE_EQ(d.gates.max_trend_inflation, 3.0);
  EXPECT_DOUBLE_EQ(d.gates.max_trend_k0_std, 2e-6);
  EXPECT_EQ(parse("bias_trend_order: 0").bias_trend_order, 0);
  EXPECT_EQ(parse("bias_trend_order: 2").bias_trend_order, 2);
  expectRefused({
      {"bias_trend_order: 3", "bias_trend_order"},
      {"bias_trend_order: -1", "bias_trend_order"},
      {"bias_trend_order: linear", "bias_trend_order"},
      {"gates: {max_trend_inflation: 0.5}", "gates.max_trend_inflation"},
      {"gates: {max_trend_k0_std: 0}", "gates.max_trend_k0_std"},
      {"gates: {max_trend_k0_std: -1e-6}", "gates.max_trend_k0_std"},
  });
}

TEST(CalibrationSettingsTest, TheFieldMethodsKeysAreReadAndChecked) {
  const FieldSettings d = parse("{}").field;
  EXPECT_EQ(d.gain_orders, (std::vector<int>{2, 4}));
  EXPECT_EQ(d.directions, (std::vector<int>{1, -1, -1, 1}));
  EXPECT_DOUBLE_EQ(d.rate, 0.2);
  EXPECT_TRUE(std::isnan(d.axis_earth_rate));  // vertical at the prior's latitude
  EXPECT_TRUE(std::isnan(parse("field: {axis_earth_rate: vertical}").field.axis_earth_rate));
  EXPECT_DOUBLE_EQ(parse("field: {axis_earth_rate: -3.1e-5}").field.axis_earth_rate, -3.1e-5);
  const FieldSettings f = parse(
                              "field: {gain_orders: [2], rate: 0.5, turns: 3, directions: [-1, 1], rest: 0, min_turns: "
                              "2, max_excess_scatter: 1.5, max_gain_error: 0.01, max_drift_std: 2.0e-8}")
                              .field;
  EXPECT_EQ(f.gain_orders, (std::vector<int>{2}));
  EXPECT_DOUBLE_EQ(f.rate, 0.5);
  EXPECT_DOUBLE_EQ(f.turns, 3.0);
  EXPECT_EQ(f.directions, (std::vector<int>{-1, 1}));
  EXPECT_DOUBLE_EQ(f.rest, 0.0);
  EXPECT_DOUBLE_EQ(f.min_turns, 2.0);
  EXPECT_DOUBLE_EQ(f.max_excess_scatter, 1.5);
  EXPECT_DOUBLE_EQ(f.max_gain_error, 0.01);
  EXPECT_DOUBLE_EQ(f.max_drift_std, 2e-8);
  expectRefused({
      {"field: {rate: 0}", "field.rate"},
      {"field: {rate: 11}", "field.rate"},
      {"field: {rate: .nan}", "field.rate"},
      {"field: {turns: -1}", "field.turns"},
      {"field: {directions: []}", "field.directions"},
      {"field: {directions: [1, 2]}", "field.directions[1]"},
      {"field: {directions: [1, 1]}", "field.directions"},          // one way cannot pass
      {"field: {axis_earth_rate: 1e-4}", "field.axis_earth_rate"},  // beyond the Earth's rate
      {"field: {axis_earth_rate: up}", "field.axis_earth_rate"},
      {"field: {rest: -1}", "field.rest"},
  });
  EXPECT_EQ(keyOf("field: {gain_orders: [3]}").rfind("field.gain_orders", 0), 0u);
  expectRefused({
      {"field: {max_excess_scatter: 0.5}", "field.max_excess_scatter"},
      {"field: {max_drift_std: 0}", "field.max_drift_std"},
      {"field: {speed: 1}", "field.speed"},
      {"field: 1", "field"},
  });
}

// Every key that sets the plan's length is bounded and refused by name beyond its bound, so that no
// plan runs for ever (turns: 1e308 did); within the bounds, a plan longer than a day is refused too
// when the field method is the one that will run it (the plateau's settle time counts).
TEST(CalibrationSettingsTest, TheFieldPlansLengthIsBoundedKeyByKeyAndWhole) {
  expectRefused({
      {"field: {turns: 1e308}", "field.turns"},
      {"field: {turns: 100.5}", "field.turns"},
      {"field: {turns: 0}", "field.turns"},
      {"field: {turns: .inf}", "field.turns"},
      {"field: {rest: 1e308}", "field.rest"},
      {"field: {rest: 601}", "field.rest"},
      {"field: {rate: 1e-300}", "field.rate"},
      {"field: {rate: 0.009}", "field.rate"},
      {"field: {directions: [1, -1, 1, -1, 1, -1, 1, -1, 1, -1, 1, -1, 1, -1, 1, -1, 1]}", "field.directions"},
      {"field: {turns: 100, rate: 10, rest: 600, directions: [1, -1, 1, -1, 1, -1, 1, -1, 1, -1, 1, "
       "-1, 1, -1, 1, -1]}",
       "accepted"},  // every bound reached, 16 x 66 s
  });
  // Each key within its bound, the plan not: 2 segments of 100 turns at 0.01 rad/s are 35 h.
  expectRefused({
      {"method: field\nfield: {rate: 0.01, turns: 100, directions: [1, -1]}", "field"},
      {"method: dual_rate\nfield: {rate: 0.01, turns: 100, directions: [1, -1]}", "accepted"},
      {"method: field\nfield: {rate: 0.01, turns: 50, directions: [1, -1]}", "accepted"},  // 17.5 h
      {"method: field\nplateau: {settle_time: 1e308}", "field"},
  });
  try {
    parse("method: field\nfield: {rate: 0.01, turns: 100, directions: [1, -1]}");
  } catch (const ConfigError& e) {
    std::printf("[ refused ] %s\n", e.what());
    EXPECT_NE(std::string(e.what()).find("more than 86400 s"), std::string::npos) << e.what();
  }
}

// field/resonator: 'unknown' (the default), or the gyro's shell, loops and drive under the names of
// a scenario's dynamics section, every value the lag's prediction uses required.
TEST(CalibrationSettingsTest, TheGyrosResonatorIsUnknownOrGivenWithEveryValueThePredictionUses) {
  EXPECT_FALSE(parse("{}").field.resonator.has_value());
  EXPECT_FALSE(parse("field: {resonator: unknown}").field.resonator.has_value());
  const std::string shell =
      "shell: {bryan_factor: 0.28, damping_time: 600.0, damping_anisotropy: 4.0e-5, damping_axis: 0.4, "
      "frequency_split: 0.031416, frequency_axis: -0.7}";
  const std::string loops =
      "loops: {energy_bandwidth: 5.0, quadrature_bandwidth: 20.0, phase_bandwidth: 20.0, damping_ratio: 0.7071, "
      "control_rate: 5000.0}";
  const std::string drive =
      "drive: {gain_error_c: 2.0e-3, gain_error_s: -1.0e-3, phase_error: 1.0e-3, virtual_rate_gain_error: 3.0e-3}";
  const auto with = [](const std::string& resonator) { return "field: {resonator: {" + resonator + "}}"; };
  const std::optional<FieldResonator> r = parse(with(shell + ", " + loops + ", " + drive)).field.resonator;
  ASSERT_TRUE(r.has_value());
  EXPECT_DOUBLE_EQ(r->shell.frequency_split, 0.031416);
  EXPECT_DOUBLE_EQ(r->shell.frequency_axis, -0.7);
  EXPECT_DOUBLE_EQ(r->shell.damping_anisotropy, 4e-5);
  EXPECT_DOUBLE_EQ(r->shell.damping_axis, 0.4);
  EXPECT_DOUBLE_EQ(r->loops.quadrature_bandwidth, 20.0);
  EXPECT_DOUBLE_EQ(r->loops.energy_bandwidth, 5.0);
  EXPECT_DOUBLE_EQ(r->loops.damping_ratio, 0.7071);
  EXPECT_DOUBLE_EQ(r->loops.control_rate, 5000.0);
  EXPECT_DOUBLE_EQ(r->drive.gain_error_c, 2e-3);
  EXPECT_DOUBLE_EQ(r->drive.gain_error_s, -1e-3);
  EXPECT_DOUBLE_EQ(r->drive.phase_error, 1e-3);
  EXPECT_EQ(keyOf("field: {resonator: known}"), "field.resonator");
  EXPECT_EQ(keyOf(with(shell + ", " + loops)), "field.resonator.drive");
  EXPECT_EQ(keyOf(with(shell + ", " + loops + ", " + drive + ", pickoff: {}")), "field.resonator.pickoff");
  EXPECT_EQ(
      keyOf(with("shell: {frequency_split: 0.03, frequency_axis: 0, damping_anisotropy: 0}, " + loops + ", " + drive)),
      "field.resonator.shell.damping_axis");  // nothing unknown is taken for zero
  EXPECT_EQ(keyOf(with(shell + ", " + loops + ", drive: {gain_error_c: 0, gain_error_s: 0, phase_error: 2}")),
            "field.resonator.drive");  // |phase| < pi/2
  EXPECT_EQ(keyOf(with(shell +
                       ", loops: {energy_bandwidth: 5, quadrature_bandwidth: 0, damping_ratio: 0.7, "
                       "control_rate: 5000}, " +
                       drive)),
            "field.resonator");  // a split with the quadrature loop open: nothing settles
}

TEST(CalibrationSettingsTest, KeyPathsListEveryKeyOnce) {
  const std::vector<std::string> keys = CalibrationSettings::keyPaths();
  for (const char* k : {"bias_trend_order", "gates/max_trend_inflation", "gates/max_trend_k0_std", "field/rate",
                        "field/directions", "field/gain_orders", "field/resonator"}) {
    EXPECT_EQ(std::count(keys.begin(), keys.end(), k), 1) << k;
  }
  // A former name is read but not listed: the template, which must hold every listed key, gives the new one.
  EXPECT_EQ(std::count(keys.begin(), keys.end(), "backward_persist"), 0);
  const std::vector<std::string> former = CalibrationSettings::formerKeyPaths();
  EXPECT_EQ(std::count(former.begin(), former.end(), "backward_persist"), 1);
}

// Each range check says the range it applies: the bounds of the message are accepted, a step beyond
// them refused with the key named.
TEST(CalibrationSettingsTest, RangeChecksMatchTheirMessages) {
  EXPECT_DOUBLE_EQ(parse("table_clock: {window: 1}").table_clock.window, 1.0);
  EXPECT_DOUBLE_EQ(parse("table_clock: {window: 600}").table_clock.window, 600.0);
  expectRefused({
      {"table_clock: {window: 0.999}", "table_clock.window"},
      {"table_clock: {window: 600.001}", "table_clock.window"},
      {"table_clock: {window: 1000}", "table_clock.window"},
  });
  try {
    parse("table_clock: {window: 1000}");
  } catch (const ConfigError& e) {
    EXPECT_NE(e.problem().find("[1, 600] s"), std::string::npos) << e.what();
  }
  EXPECT_DOUBLE_EQ(parse("table_clock: {offset: -3600}").table_clock.offset, -3600.0);
  EXPECT_EQ(keyOf("table_clock: {offset: 3600.5}"), "table_clock.offset");
  EXPECT_EQ(parse("bins: 8").bins, 8);
  EXPECT_EQ(parse("bins: 4096").bins, 4096);
  EXPECT_EQ(keyOf("bins: 4097"), "bins");
  EXPECT_EQ(parse("jump_persist: 1000").jump_persist, 1000);
  EXPECT_EQ(keyOf("jump_persist: 1001"), "jump_persist");
  EXPECT_EQ(parse("backward_persist: 7").jump_persist, 7);  // its former name
  expectRefused({
      {"backward_persist: 1001", "backward_persist"},
      {"{backward_persist: 5, jump_persist: 5}", "backward_persist"},
  });
  EXPECT_DOUBLE_EQ(parse("forward_jump: 600").forward_jump, 600.0);
  expectRefused({
      {"forward_jump: 600.5", "forward_jump"},
      {"forward_jump: 0", "forward_jump"},
  });
  EXPECT_DOUBLE_EQ(parse("plateau: {smoothing_span: 20}").plateau.smoothing_span, 20.0);
  EXPECT_EQ(keyOf("plateau: {smoothing_span: 20.5}"), "plateau.smoothing_span");
  EXPECT_DOUBLE_EQ(parse("gates: {min_coverage: 1}").gates.min_coverage, 1.0);
  EXPECT_EQ(keyOf("gates: {min_coverage: 1.01}"), "gates.min_coverage");
  EXPECT_DOUBLE_EQ(parse("field: {rate: 10}").field.rate, 10.0);
  EXPECT_EQ(keyOf("field: {rate: 10.5}"), "field.rate");
  EXPECT_EQ(parse("thermal: {node_count: 32}").thermal.node_count, 32);
  EXPECT_EQ(keyOf("thermal: {node_count: 33}"), "thermal.node_count");
  EXPECT_EQ(parse("thermal: {max_slices: 100000}").thermal.max_slices, 100000);
  EXPECT_EQ(keyOf("thermal: {max_slices: 100001}"), "thermal.max_slices");
}

}  // namespace
}  // namespace core
}  // namespace hrg_gyro
