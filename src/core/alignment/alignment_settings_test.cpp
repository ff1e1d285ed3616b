// The alignment's settings: every bad value refused naming its key; the mode's names; the noise terms
// an Allan deviation identified replace the defaults, also read from `hrg_bag allan --yaml`'s file
// (noise/allan_file); the YAML form: every key read from a file, an
// unknown key and a bad value refused by name, the shipped node template a settings file too.
#include "hrg_gyro/core/alignment/alignment_settings.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>

#include "core/testing/refusal.h"
#include "core/testing/temporary_file.h"
#include "hrg_gyro/core/alignment/local_level.h"
#include "hrg_gyro/core/common/yaml_field.h"
#include "hrg_gyro/core/estimation/allan_readings_file.h"

namespace hrg_gyro {
namespace core {
namespace {

std::string validateRefusal(const std::function<void(AlignmentSettings*)>& change) {
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
  EXPECT_EQ(validateRefusal([](AlignmentSettings*) {}), "");
  EXPECT_EQ(validateRefusal([](AlignmentSettings* s) { s->latitude = NAN; }), "latitude");
  EXPECT_EQ(validateRefusal([](AlignmentSettings* s) { s->latitude = 2.0; }), "latitude");
  EXPECT_EQ(validateRefusal([](AlignmentSettings* s) { s->max_latitude = 1.6; }), "max_latitude");
  EXPECT_EQ(validateRefusal([](AlignmentSettings* s) { s->duration = 0.0; }), "duration");
  EXPECT_EQ(validateRefusal([](AlignmentSettings* s) { s->duration = 1e6; }), "duration");
  EXPECT_EQ(validateRefusal([](AlignmentSettings* s) { s->single_gyro = true; }), "single_gyro");
  EXPECT_EQ(validateRefusal([](AlignmentSettings* s) { s->noise.angle_white_noise = 0.0; }), "noise/angle_white_noise");
  EXPECT_EQ(validateRefusal([](AlignmentSettings* s) { s->noise.rate_random_walk = -1.0; }), "noise/rate_random_walk");
  EXPECT_EQ(validateRefusal([](AlignmentSettings* s) { s->noise.residual_bias = INFINITY; }), "noise/residual_bias");
  // Not given (NaN) is no error of the value: requireComplete() refuses it where a budget needs it.
  EXPECT_EQ(validateRefusal([](AlignmentSettings* s) { s->noise.residual_bias = NAN; }), "");
  EXPECT_EQ(validateRefusal([](AlignmentSettings* s) { s->motion.step_threshold = 0.0; }), "motion/step_threshold");
  EXPECT_EQ(validateRefusal([](AlignmentSettings* s) { s->motion.max_excluded = 0.95; }), "motion/max_excluded");
  EXPECT_EQ(validateRefusal([](AlignmentSettings* s) { s->motion.block_false_alarm = 0.5; }),
            "motion/block_false_alarm");
  EXPECT_EQ(validateRefusal([](AlignmentSettings* s) { s->max_earth_sigmas = -1.0; }), "max_earth_sigmas");
  EXPECT_EQ(validateRefusal([](AlignmentSettings* s) { s->level.accelerometer_mounting_sigma = -1e-3; }),
            "level/accelerometer_mounting_sigma");
  EXPECT_EQ(validateRefusal([](AlignmentSettings* s) {
              s->level.source = LevelSource::kDeclared;
              s->level.roll_sigma = -1e-3;
            }),
            "level/roll_sigma");
  EXPECT_EQ(validateRefusal([](AlignmentSettings* s) { s->level.accelerometer_to_body.coeffs() << 0, 0, 0, 2; }),
            "level/accelerometer_to_body");
  EXPECT_EQ(validateRefusal([](AlignmentSettings* s) { s->indexer.body_to_platform(0, 0) = 2.0; }),
            "indexer/body_to_platform");
  EXPECT_EQ(validateRefusal([](AlignmentSettings* s) { s->indexer.gyro_axis = Eigen::Vector3d(1, 1, 0); }),
            "indexer/gyro_axis");
  EXPECT_EQ(validateRefusal([](AlignmentSettings* s) { s->sweep.gain_orders = {0}; }), "sweep/gain_orders");
  EXPECT_EQ(validateRefusal([](AlignmentSettings* s) { s->motion.max_scatter = 0.5; }), "motion/max_scatter");
  EXPECT_EQ(validateRefusal([](AlignmentSettings* s) { s->motion.block = 0.0; }), "motion/block");
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

// Every key of the interface with a value other than its default, and the node's own keys beside them.
const char* const kFullFile = R"(
mode: indexed
latitude: 0.9
max_latitude: 1.2
duration: 60.5
single_gyro: true
max_earth_rate_error: 0.3
max_earth_sigmas: 6.0
max_estimator_sigmas: 3.5
estimator: still_base
max_condition: 1.0e7
gyro_input: triad
imu:
  mounting: {roll: 3.141592653589793, pitch: 0.0, yaw: 0.0}
  period: 0.005
  max_bridge: 3.0
  rate_variance: 1.0e-10
  max_rate: 10.0
  accelerometer: false
  body_frame: base_link
noise:
  angle_quantum: 4.8e-7
  angle_white_noise: 8.8e-6
  angle_random_walk: 1.5e-7
  rate_random_walk: 2.0e-10
  residual_bias: 3.0e-9
  residual_drift_harmonics: 4.0e-9
level:
  source: declared
  roll: 0.01
  pitch: -0.02
  roll_sigma: 1.0e-4
  pitch_sigma: 2.0e-4
  accelerometer_to_body: {roll: 0.1, pitch: -0.2, yaw: 0.3}
  accelerometer_bias_sigma: 1.0e-3
  accelerometer_mounting_sigma: 2.0e-3
  max_gravity_error: 0.05
indexer:
  continuous: true
  body_to_platform: {roll: 0.0, pitch: 0.0, yaw: 1.5707963267948966}
  gyro_axis: [0.0, 1.0, 0.0]
  rest_rate: 2.0e-3
  settle: 0.5
  position_tolerance: 2.0e-3
  max_record_gap: 0.25
  angle_sigma: 1.0e-5
sweep:
  settle: 3.0
  gain_orders: [2, 4, 6]
  min_turns: 2.0
motion:
  block: 4.0
  max_motion: 2.0e-4
  max_scatter: 2.0
  step_threshold: 50.0
  step_guard: 0.7
  max_steps: 5
  max_excluded: 0.2
  block_false_alarm: 1.0e-3
align_at_startup: true
triad_file: ""
hold: {enabled: true, covariance_interval: 0.2}
queue_size: 10
diagnostic_period: 1.0
)";

AlignmentSettings parseText(const std::string& text) {
  return AlignmentSettings::parse(YamlField(YAML::Load(text), ""), AlignmentSettings::nodeKeys());
}

TEST(AlignmentSettingsTest, EveryKeyIsReadFromAFile) {
  const TemporaryFile file("hrg_alignment_settings_full", kFullFile);
  const AlignmentSettings s = AlignmentSettings::load(file.path());
  EXPECT_EQ(s.mode, AlignmentMode::kIndexed);
  EXPECT_EQ(s.latitude, 0.9);
  EXPECT_EQ(s.max_latitude, 1.2);
  EXPECT_EQ(s.duration, 60.5);
  EXPECT_TRUE(s.single_gyro);
  EXPECT_EQ(s.max_earth_rate_error, 0.3);
  EXPECT_EQ(s.max_condition, 1e7);
  EXPECT_EQ(s.max_earth_sigmas, 6.0);
  EXPECT_EQ(s.max_estimator_sigmas, 3.5);
  EXPECT_EQ(s.estimator, EstimatorChoice::kStillBase);
  EXPECT_NE(s.noise_sources.residual_bias.find("settings"), std::string::npos);
  EXPECT_EQ(s.noise.angle_white_noise, 8.8e-6);
  EXPECT_EQ(s.noise.angle_random_walk, 1.5e-7);
  EXPECT_EQ(s.noise.rate_random_walk, 2e-10);
  EXPECT_EQ(s.noise.residual_bias, 3e-9);
  EXPECT_EQ(s.noise.residual_drift_harmonics, 4e-9);
  EXPECT_EQ(s.noise.angle_quantum, 4.8e-7);
  EXPECT_EQ(s.gyro_input, GyroInput::kTriad);
  EXPECT_NEAR(s.imu.converter.imu_to_body.angularDistance(Eigen::Quaterniond(0, 1, 0, 0)), 0.0, 1e-12);
  EXPECT_EQ(s.imu.converter.period, 0.005);
  EXPECT_EQ(s.imu.converter.max_bridge, 3.0);
  EXPECT_EQ(s.imu.converter.fallback_rate_variance, 1e-10);
  EXPECT_EQ(s.imu.converter.max_rate, 10.0);
  EXPECT_FALSE(s.imu.accelerometer);
  EXPECT_EQ(s.imu.body_frame, "base_link");
  EXPECT_EQ(s.level.source, LevelSource::kDeclared);
  EXPECT_EQ(s.level.roll, 0.01);
  EXPECT_EQ(s.level.pitch, -0.02);
  EXPECT_EQ(s.level.roll_sigma, 1e-4);
  EXPECT_EQ(s.level.pitch_sigma, 2e-4);
  const EulerAngles mount = eulerFromOrientation(s.level.accelerometer_to_body);
  EXPECT_NEAR(mount.roll, 0.1, 1e-15);
  EXPECT_NEAR(mount.pitch, -0.2, 1e-15);
  EXPECT_NEAR(mount.yaw, 0.3, 1e-15);
  EXPECT_EQ(s.level.accelerometer_bias_sigma, 1e-3);
  EXPECT_EQ(s.level.accelerometer_mounting_sigma, 2e-3);
  EXPECT_EQ(s.level.max_gravity_error, 0.05);
  EXPECT_TRUE(s.indexer.continuous);
  // A quarter turn about z: the body's x is the platform's y.
  EXPECT_NEAR((s.indexer.body_to_platform * Eigen::Vector3d::UnitX() - Eigen::Vector3d::UnitY()).norm(), 0.0, 1e-15);
  EXPECT_EQ(s.indexer.gyro_axis, Eigen::Vector3d::UnitY());
  EXPECT_EQ(s.indexer.rest_rate, 2e-3);
  EXPECT_EQ(s.indexer.settle, 0.5);
  EXPECT_EQ(s.indexer.position_tolerance, 2e-3);
  EXPECT_EQ(s.indexer.max_record_gap, 0.25);
  EXPECT_EQ(s.indexer.angle_sigma, 1e-5);
  EXPECT_EQ(s.sweep.settle, 3.0);
  EXPECT_EQ(s.sweep.gain_orders, (std::vector<int>{2, 4, 6}));
  EXPECT_EQ(s.sweep.min_turns, 2.0);
  EXPECT_EQ(s.motion.block, 4.0);
  EXPECT_EQ(s.motion.max_motion, 2e-4);
  EXPECT_EQ(s.motion.max_scatter, 2.0);
  EXPECT_EQ(s.motion.step_threshold, 50.0);
  EXPECT_EQ(s.motion.step_guard, 0.7);
  EXPECT_EQ(s.motion.max_steps, 5);
  EXPECT_EQ(s.motion.max_excluded, 0.2);
  EXPECT_EQ(s.motion.block_false_alarm, 1e-3);
  // keyPaths() names every key the file gives (the node's own aside).
  const std::vector<std::string> paths = AlignmentSettings::keyPaths();
  EXPECT_EQ(paths.size(), 11u + 7u + 9u + 8u + 3u + 8u + 7u);
  for (const char* key : {"mode", "noise/residual_drift_harmonics", "level/accelerometer_to_body", "indexer/gyro_axis",
                          "sweep/gain_orders", "motion/max_scatter"}) {
    EXPECT_NE(std::find(paths.begin(), paths.end(), key), paths.end()) << key;
  }
}

TEST(AlignmentSettingsTest, AnImuIsTheGyroInputOfTheTriadModesOnly) {
  const TemporaryFile imu(
      "hrg_alignment_settings_imu",
      "latitude: 0.6\ngyro_input: imu\nimu: {mounting: {yaw: -1.5707963267948966}, period: 0.01}\n");
  const AlignmentSettings s = AlignmentSettings::load(imu.path());
  EXPECT_EQ(s.gyro_input, GyroInput::kImu);
  EXPECT_NEAR((s.imu.converter.imu_to_body * Eigen::Vector3d::UnitY() - Eigen::Vector3d::UnitX()).norm(), 0.0, 1e-12)
      << "right-front-up: the IMU's y is the body's x";
  auto key = [](const std::string& text) {
    const TemporaryFile f("hrg_alignment_settings_imu_bad", "latitude: 0.6\n" + text);
    return refusedKey([&] { AlignmentSettings::load(f.path()); });
  };
  EXPECT_EQ(key("gyro_input: imu\nmode: sweep\n"), "gyro_input");
  EXPECT_EQ(key("gyro_input: imu\nmode: indexed\nsingle_gyro: true\n"), "gyro_input");
  EXPECT_EQ(key("gyro_input: fog\n"), "gyro_input");
  EXPECT_EQ(key("imu: {period: -1.0}\n"), "imu.period");
  EXPECT_EQ(key("imu: {mounting: {heading: 1.0}}\n"), "imu.mounting.heading");
  EXPECT_EQ(key("imu: {lever_arm: [0, 0, 0]}\n"), "imu.lever_arm");
  EXPECT_EQ(key("noise: {angle_quantum: -1.0e-7}\n"), "noise.angle_quantum");
}

TEST(AlignmentSettingsTest, UnknownKeysAndBadValuesAreRefusedByName) {
  const std::string base = "latitude: 0.9\n";
  EXPECT_EQ(refusedKey([&] { parseText(base); }), "accepted");
  EXPECT_EQ(refusedKey([&] { parseText(base + "latitud: 0.9\n"); }), "latitud");
  EXPECT_EQ(refusedKey([&] { parseText(base + "noise: {residual_biass: 1.0e-9}\n"); }), "noise.residual_biass");
  EXPECT_EQ(refusedKey([&] { parseText(base + "level: {accelerometer_to_body: {rol: 0.1}}\n"); }),
            "level.accelerometer_to_body.rol");
  // The node's own keys only where the caller allows them.
  EXPECT_EQ(refusedKey([&] { AlignmentSettings::parse(YamlField(YAML::Load(base + "align_at_startup: true"), "")); }),
            "align_at_startup");
  // Bad values: a type, a rule of validate(), a name.
  EXPECT_EQ(refusedKey([&] { parseText("latitude: north\n"); }), "latitude");
  EXPECT_EQ(refusedKey([&] { parseText(""); }), "");  // not a map: the document itself
  EXPECT_EQ(refusedKey([&] { parseText("mode: static\n"); }), "latitude");
  EXPECT_EQ(refusedKey([&] { parseText(base + "mode: gyrocompass\n"); }), "mode");
  EXPECT_EQ(refusedKey([&] { parseText(base + "noise: {residual_bias: -1.0e-9}\n"); }), "noise.residual_bias");
  EXPECT_EQ(refusedKey([&] { parseText(base + "level: {source: declared, roll_sigma: -1.0}\n"); }), "level.roll_sigma");
  EXPECT_EQ(refusedKey([&] { parseText(base + "level: {source: magnetometer}\n"); }), "level.source");
  EXPECT_EQ(refusedKey([&] { parseText(base + "indexer: {gyro_axis: [1.0, 1.0, 0.0]}\n"); }), "indexer.gyro_axis");
  EXPECT_EQ(refusedKey([&] { parseText(base + "indexer: {gyro_axis: [1.0, 0.0]}\n"); }), "indexer.gyro_axis");
  EXPECT_EQ(refusedKey([&] { parseText(base + "sweep: {gain_orders: [2, 400000000000]}\n"); }), "sweep.gain_orders");
  EXPECT_EQ(refusedKey([&] { parseText(base + "motion: {max_scatter: 0.5}\n"); }), "motion.max_scatter");
  EXPECT_EQ(refusedKey([&] { parseText(base + "single_gyro: true\n"); }), "single_gyro");
  // A file that cannot be read, or is no YAML, is refused with its name.
  try {
    AlignmentSettings::load("/nonexistent/gyrocompass.yaml");
    FAIL();
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/gyrocompass.yaml"), std::string::npos) << e.what();
  }
  const TemporaryFile broken("hrg_alignment_settings_broken", "latitude: [0.9\n");
  EXPECT_EQ(refusedKey([&] { AlignmentSettings::load(broken.path()); }), "");
}

// noise/allan_file: the readings a record's Allan deviation identified (Q and K here) replace their
// keys, one it did not (N) keeps its key; a relative path is the settings file's neighbour, and is
// refused where there is no settings file (the node's parameters); a missing file names the key.
TEST(AlignmentSettingsTest, TheNoiseComesFromAnAllanReadingsFile) {
  AllanReadings readings;
  readings.samples = 72000;
  readings.tau0 = 0.005;
  readings.result.angle_white_noise = {true, 4.9e-6, 0.005, 0.05};
  readings.result.angle_random_walk = {false, 0.0, 0.0, 0.0};
  readings.result.bias_instability = {true, 3e-9, 20.0, 60.0};
  readings.result.rate_random_walk = {true, 5e-10, 100.0, 300.0};
  const TemporaryFile allan("hrg_alignment_allan", allanReadingsYaml(readings));
  const std::string name = std::filesystem::path(allan.path()).filename().string();
  const TemporaryFile file("hrg_alignment_settings_allan",
                           "latitude: 0.9\nnoise:\n  allan_file: " + name +
                               "\n  angle_random_walk: 1.5e-7\n  rate_random_walk: 1e-9\n"
                               "  residual_bias: 1e-8\n");
  const AlignmentSettings s = AlignmentSettings::load(file.path());
  EXPECT_EQ(s.noise.angle_white_noise, 4.9e-6);
  EXPECT_EQ(s.noise.angle_random_walk, 1.5e-7);  // not identified: the key's
  EXPECT_EQ(s.noise.rate_random_walk, 5e-10);    // the file's, not the key's
  EXPECT_EQ(s.noise.residual_bias, 1e-8);
  EXPECT_EQ(s.allan_tau0, 0.005);
  // A quantum beside the file: the white noise's source says both (the file's Q, the count's q^2/12).
  const AlignmentSettings q =
      parseText("latitude: 0.9\nnoise: {angle_quantum: 4.8e-7, allan_file: " + allan.path() + "}\n");
  EXPECT_NE(q.noise_sources.angle_white_noise.find("allan_file"), std::string::npos)
      << q.noise_sources.angle_white_noise;
  EXPECT_NE(q.noise_sources.angle_white_noise.find("angle quantum"), std::string::npos)
      << q.noise_sources.angle_white_noise;
  const std::string base = "latitude: 0.9\n";
  EXPECT_EQ(refusedKey([&] { parseText(base + "noise: {allan_file: " + name + "}\n"); }), "noise.allan_file");
  EXPECT_EQ(parseText(base + "noise: {allan_file: " + allan.path() + "}\n").noise.rate_random_walk, 5e-10);
  EXPECT_TRUE(std::isnan(parseText(base + "noise: {allan_file: ''}\n").noise.rate_random_walk));  // "": none, unset
  EXPECT_EQ(refusedKey([&] { parseText(base + "noise: {allan_file: /nonexistent/allan.yaml}\n"); }),
            "noise.allan_file");
  const TemporaryFile bad("hrg_alignment_allan_bad", "samples: 10\ntau0: 0.005\n");
  EXPECT_EQ(refusedKey([&] { parseText(base + "noise: {allan_file: " + bad.path() + "}\n"); }), "noise.allan_file");
}

// The node's parameter template is a settings file too: every key in it is valid, and its one
// missing key is the site's latitude, which has no default.
TEST(AlignmentSettingsTest, TheNodeTemplateIsASettingsFile) {
  const std::string shipped = std::string(HRG_GYRO_SOURCE_DIR) + "/config/gyrocompass.yaml";
  EXPECT_EQ(refusedKey([&] { AlignmentSettings::load(shipped); }), "latitude");
  std::ifstream in(shipped);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const TemporaryFile file("hrg_alignment_settings_template", text + "latitude: 0.9\n");
  const AlignmentSettings s = AlignmentSettings::load(file.path());
  const AlignmentSettings defaults;
  EXPECT_EQ(s.mode, defaults.mode);
  EXPECT_EQ(s.duration, defaults.duration);
  EXPECT_EQ(s.max_latitude, defaults.max_latitude);
  EXPECT_EQ(s.level.source, defaults.level.source);
  EXPECT_EQ(s.noise.angle_white_noise, defaults.noise.angle_white_noise);
  EXPECT_EQ(s.motion.max_scatter, defaults.motion.max_scatter);
  EXPECT_EQ(s.sweep.gain_orders, defaults.sweep.gain_orders);
}

}  // namespace
}  // namespace core
}  // namespace hrg_gyro
