// The calibrator settings as the node and `hrg_bag calibrate --config` read them: the defaults, and
// every bad value refused with the key named.
#include "hrg_gyro/core/calibration/calibration_settings.h"

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <string>
#include <vector>

namespace hrg_gyro {
namespace core {
namespace {

CalibrationSettings parse(const std::string& yaml) {
  return CalibrationSettings::parse(YamlField(YAML::Load(yaml), ""));
}

/// The key a refusal names ("" when nothing is refused).
std::string refusedKey(const std::string& yaml) {
  try {
    parse(yaml);
  } catch (const ConfigError& e) {
    return e.key();
  }
  return "";
}

TEST(CalibrationSettingsTest, TheBiasTrendIsLinearByDefaultAndItsKeysAreChecked) {
  const CalibrationSettings d = parse("{}");
  EXPECT_EQ(d.bias_trend_order, 1);
  EXPECT_DOUBLE_EQ(d.gates.max_trend_inflation, 3.0);
  EXPECT_DOUBLE_EQ(d.gates.max_trend_k0_std, 2e-6);
  EXPECT_EQ(parse("bias_trend_order: 0").bias_trend_order, 0);
  EXPECT_EQ(parse("bias_trend_order: 2").bias_trend_order, 2);
  EXPECT_EQ(refusedKey("bias_trend_order: 3"), "bias_trend_order");
  EXPECT_EQ(refusedKey("bias_trend_order: -1"), "bias_trend_order");
  EXPECT_EQ(refusedKey("bias_trend_order: linear"), "bias_trend_order");
  EXPECT_EQ(refusedKey("gates: {max_trend_inflation: 0.5}"), "gates.max_trend_inflation");
  EXPECT_EQ(refusedKey("gates: {max_trend_k0_std: 0}"), "gates.max_trend_k0_std");
  EXPECT_EQ(refusedKey("gates: {max_trend_k0_std: -1e-6}"), "gates.max_trend_k0_std");
}

TEST(CalibrationSettingsTest, KeyPathsListEveryKeyOnce) {
  const std::vector<std::string> keys = CalibrationSettings::keyPaths();
  for (const char* k : {"bias_trend_order", "gates/max_trend_inflation", "gates/max_trend_k0_std"}) {
    EXPECT_EQ(std::count(keys.begin(), keys.end(), k), 1) << k;
  }
}

}  // namespace
}  // namespace core
}  // namespace hrg_gyro
