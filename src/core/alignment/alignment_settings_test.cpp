// The alignment's settings: every bad value refused naming its key; the mode's names; the noise terms
// an Allan deviation identified replace the defaults.
#include "hrg_gyro/core/alignment/alignment_settings.h"

#include <gtest/gtest.h>

#include <functional>

#include "hrg_gyro/core/common/yaml_field.h"

namespace hrg_gyro {
namespace core {
namespace {

std::string refusedKey(const std::function<void(AlignmentSettings*)>& change) {
  AlignmentSettings s;
  s.latitude = 0.9;
  change(&s);
  try {
    s.validate();
  } catch (const ConfigError& e) {
    return e.key();
  }
  return "";
}

TEST(AlignmentSettingsTest, BadValuesAreRefusedNamingTheKey) {
  EXPECT_EQ(refusedKey([](AlignmentSettings*) {}), "");
  EXPECT_EQ(refusedKey([](AlignmentSettings* s) { s->latitude = NAN; }), "latitude");
  EXPECT_EQ(refusedKey([](AlignmentSettings* s) { s->latitude = 2.0; }), "latitude");
  EXPECT_EQ(refusedKey([](AlignmentSettings* s) { s->max_latitude = 1.6; }), "max_latitude");
  EXPECT_EQ(refusedKey([](AlignmentSettings* s) { s->duration = 0.0; }), "duration");
  EXPECT_EQ(refusedKey([](AlignmentSettings* s) { s->duration = 1e6; }), "duration");
  EXPECT_EQ(refusedKey([](AlignmentSettings* s) { s->single_gyro = true; }), "single_gyro");
  EXPECT_EQ(refusedKey([](AlignmentSettings* s) { s->noise.angle_white_noise = 0.0; }), "noise/angle_white_noise");
  EXPECT_EQ(refusedKey([](AlignmentSettings* s) { s->noise.rate_random_walk = -1.0; }), "noise/rate_random_walk");
  EXPECT_EQ(refusedKey([](AlignmentSettings* s) { s->noise.residual_bias = NAN; }), "noise/residual_bias");
  EXPECT_EQ(refusedKey([](AlignmentSettings* s) {
              s->level.source = LevelSource::kDeclared;
              s->level.roll_sigma = -1e-3;
            }),
            "level/roll_sigma");
  EXPECT_EQ(refusedKey([](AlignmentSettings* s) { s->level.accelerometer_to_body.coeffs() << 0, 0, 0, 2; }),
            "level/accelerometer_to_body");
  EXPECT_EQ(refusedKey([](AlignmentSettings* s) { s->indexer.body_to_platform(0, 0) = 2.0; }),
            "indexer/body_to_platform");
  EXPECT_EQ(refusedKey([](AlignmentSettings* s) { s->indexer.gyro_axis = Eigen::Vector3d(1, 1, 0); }),
            "indexer/gyro_axis");
  EXPECT_EQ(refusedKey([](AlignmentSettings* s) { s->sweep.gain_orders = {0}; }), "sweep/gain_orders");
  EXPECT_EQ(refusedKey([](AlignmentSettings* s) { s->motion.max_scatter = 0.5; }), "motion/max_scatter");
  EXPECT_EQ(refusedKey([](AlignmentSettings* s) { s->motion.block = 0.0; }), "motion/block");
}

TEST(AlignmentSettingsTest, ModesAndAllanReadings) {
  EXPECT_EQ(parseAlignmentMode("static"), AlignmentMode::kStatic);
  EXPECT_EQ(parseAlignmentMode("indexed"), AlignmentMode::kIndexed);
  EXPECT_EQ(parseAlignmentMode("sweep"), AlignmentMode::kSweep);
  EXPECT_STREQ(toString(AlignmentMode::kSweep), "sweep");
  try {
    parseAlignmentMode("gyrocompass", "gyrocompass/mode");
    FAIL();
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.key(), "gyrocompass/mode");
  }
  AllanResult allan;
  allan.angle_white_noise = {true, 8.8e-6, 0.01, 0.1};
  allan.rate_random_walk = {true, 1e-9, 100, 1000};
  GyroNoiseModel base;
  base.angle_random_walk = 1e-7;
  base.residual_bias = 1e-8;
  const GyroNoiseModel n = noiseFromAllan(allan, base);
  EXPECT_EQ(n.angle_white_noise, 8.8e-6);
  EXPECT_EQ(n.angle_random_walk, 1e-7);  // not identified: kept
  EXPECT_EQ(n.rate_random_walk, 1e-9);
  EXPECT_EQ(n.residual_bias, 1e-8);
}

}  // namespace
}  // namespace core
}  // namespace hrg_gyro
