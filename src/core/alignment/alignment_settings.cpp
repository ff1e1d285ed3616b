#include "hrg_gyro/core/alignment/alignment_settings.h"

#include <algorithm>
#include <cmath>

#include "hrg_gyro/core/alignment/local_level.h"
#include "hrg_gyro/core/common/yaml_field.h"
#include "hrg_gyro/core/common/yaml_file.h"
#include "hrg_gyro/core/estimation/allan_readings_file.h"
#include "hrg_gyro/core/model/parameter_file.h"

namespace hrg_gyro {
namespace core {
namespace {

void requireFiniteAtLeast(double value, double least, const std::string& key, const char* unit) {
  if (!std::isfinite(value) || value < least) {
    throw ConfigError(key, std::string("must be finite and at least ") + std::to_string(least) + " (" + unit + ")");
  }
}
void requirePositive(double value, const std::string& key, const char* unit) {
  if (!std::isfinite(value) || !(value > 0.0)) throw ConfigError(key, std::string("must be positive (") + unit + ")");
}

// The keys, listed once: parse() refuses any other, keyPaths() lists them.
const std::vector<std::string> kScalarKeys = {"mode",
                                              "latitude",
                                              "max_latitude",
                                              "duration",
                                              "single_gyro",
                                              "max_earth_rate_error",
                                              "max_earth_sigmas",
                                              "max_estimator_sigmas",
                                              "estimator",
                                              "max_condition",
                                              "gyro_input"};
const std::vector<std::string> kNoiseKeys = {"angle_white_noise", "angle_random_walk",        "rate_random_walk",
                                             "residual_bias",     "residual_drift_harmonics", "allan_file",
                                             "angle_quantum"};
const std::vector<std::string> kLevelKeys = {"source",
                                             "roll",
                                             "pitch",
                                             "roll_sigma",
                                             "pitch_sigma",
                                             "accelerometer_to_body",
                                             "accelerometer_bias_sigma",
                                             "accelerometer_mounting_sigma",
                                             "max_gravity_error"};
const std::vector<std::string> kIndexerKeys = {"continuous", "body_to_platform",   "gyro_axis",      "rest_rate",
                                               "settle",     "position_tolerance", "max_record_gap", "angle_sigma"};
const std::vector<std::string> kSweepKeys = {"settle", "gain_orders", "min_turns"};
const std::vector<std::string> kMotionKeys = {"block",      "max_motion", "max_scatter",  "step_threshold",
                                              "step_guard", "max_steps",  "max_excluded", "block_false_alarm"};
const std::vector<std::string> kImuKeys = {"mounting", "period",        "max_bridge", "rate_variance",
                                           "max_rate", "accelerometer", "body_frame"};
const std::vector<std::string> kSections = {"noise", "level", "indexer", "sweep", "motion", "imu"};
const std::vector<std::string> kNodeKeys = {"align_at_startup", "triad_file",    "hold",
                                            "queue_size",       "stall_timeout", "diagnostic_period"};

// {roll, pitch, yaw} in rad: Rz(yaw) Ry(pitch) Rx(roll).
Eigen::Quaterniond parseRotation(const YamlField& f) {
  f.requireMap();
  f.rejectUnknownKeys({"roll", "pitch", "yaw"});
  EulerAngles a;
  a.roll = f.getDouble("roll", 0.0);
  a.pitch = f.getDouble("pitch", 0.0);
  a.yaw = f.getDouble("yaw", 0.0);
  return orientationFromEuler(a);
}

/// noise/allan_file's path as read: relative to `base_directory` (a settings file's), absolute only
/// when there is none (a node's working directory is nobody's choice).
std::string allanFilePath(const YamlField& f, const std::string& base_directory) {
  const std::string path = f.asString();
  if (!path.empty() && path.front() == '/') return path;
  if (base_directory.empty()) f.fail("must be an absolute path here (or \"\": none)");
  return base_directory + "/" + path;
}

// One noise term: the key's value when given (its source "settings"), else left unset.
void noiseTerm(const YamlField& f, const char* key, double* value, std::string* source) {
  if (!f.has(key)) return;
  *value = f[key].asDouble();
  *source = std::string("settings (noise/") + key + ")";
}

void parseNoise(const YamlField& f, GyroNoiseModel* n, NoiseSources* sources, std::string* allan_file,
                double* allan_tau0, const std::string& base_directory) {
  f.requireMap();
  f.rejectUnknownKeys(kNoiseKeys);
  noiseTerm(f, "angle_white_noise", &n->angle_white_noise, &sources->angle_white_noise);
  if (n->angle_white_noise < 0.0) sources->angle_white_noise = "measured from the window";
  noiseTerm(f, "angle_random_walk", &n->angle_random_walk, &sources->angle_random_walk);
  noiseTerm(f, "rate_random_walk", &n->rate_random_walk, &sources->rate_random_walk);
  noiseTerm(f, "residual_bias", &n->residual_bias, &sources->residual_bias);
  noiseTerm(f, "residual_drift_harmonics", &n->residual_drift_harmonics, &sources->residual_drift_harmonics);
  n->angle_quantum = f.getDouble("angle_quantum", n->angle_quantum);
  // The measured readings replace the keys above; one the record did not identify keeps its key.
  if (f.getString("allan_file", "").empty()) return;
  const YamlField file = f["allan_file"];
  try {
    const std::string path = allanFilePath(file, base_directory);
    *allan_file = path;
    const AllanReadings readings = loadAllanReadings(path);
    *allan_tau0 = readings.tau0;
    *n = noiseFromAllan(readings.result, *n, sources, "allan_file " + path);
  } catch (const ConfigError& e) {
    if (e.key() == file.path()) throw;
    file.fail(e.what());
  }
}

void parseLevel(const YamlField& f, LevelSettings* l) {
  f.requireMap();
  f.rejectUnknownKeys(kLevelKeys);
  if (f.has("source")) {
    const std::string source = f["source"].asString();
    if (source == "accelerometer") {
      l->source = LevelSource::kAccelerometer;
    } else if (source == "declared") {
      l->source = LevelSource::kDeclared;
    } else {
      f["source"].fail("'" + source + "' is not a level source: accelerometer or declared");
    }
  }
  l->roll = f.getDouble("roll", l->roll);
  l->pitch = f.getDouble("pitch", l->pitch);
  l->roll_sigma = f.getDouble("roll_sigma", l->roll_sigma);
  l->pitch_sigma = f.getDouble("pitch_sigma", l->pitch_sigma);
  if (f.has("accelerometer_to_body")) l->accelerometer_to_body = parseRotation(f["accelerometer_to_body"]);
  l->accelerometer_bias_sigma = f.getDouble("accelerometer_bias_sigma", l->accelerometer_bias_sigma);
  l->accelerometer_mounting_sigma = f.getDouble("accelerometer_mounting_sigma", l->accelerometer_mounting_sigma);
  l->max_gravity_error = f.getDouble("max_gravity_error", l->max_gravity_error);
}

void parseIndexer(const YamlField& f, IndexerSettings* x) {
  f.requireMap();
  f.rejectUnknownKeys(kIndexerKeys);
  x->continuous = f.getBool("continuous", x->continuous);
  if (f.has("body_to_platform")) x->body_to_platform = parseRotation(f["body_to_platform"]).toRotationMatrix();
  if (f.has("gyro_axis")) {
    const std::vector<double> axis = f["gyro_axis"].asDoubles(3);
    x->gyro_axis = Eigen::Vector3d(axis[0], axis[1], axis[2]);
  }
  x->rest_rate = f.getDouble("rest_rate", x->rest_rate);
  x->settle = f.getDouble("settle", x->settle);
  x->position_tolerance = f.getDouble("position_tolerance", x->position_tolerance);
  x->max_record_gap = f.getDouble("max_record_gap", x->max_record_gap);
  x->angle_sigma = f.getDouble("angle_sigma", x->angle_sigma);
}

void parseSweep(const YamlField& f, SweepSettings* w) {
  f.requireMap();
  f.rejectUnknownKeys(kSweepKeys);
  w->settle = f.getDouble("settle", w->settle);
  if (f.has("gain_orders")) {
    w->gain_orders.clear();
    for (long order : f["gain_orders"].asIntegers()) {
      w->gain_orders.push_back(static_cast<int>(std::clamp<long>(order, -1, 1000)));  // validate() judges it
    }
  }
  w->min_turns = f.getDouble("min_turns", w->min_turns);
}

void parseMotion(const YamlField& f, MotionSettings* m) {
  f.requireMap();
  f.rejectUnknownKeys(kMotionKeys);
  m->block = f.getDouble("block", m->block);
  m->max_motion = f.getDouble("max_motion", m->max_motion);
  m->max_scatter = f.getDouble("max_scatter", m->max_scatter);
  m->step_threshold = f.getDouble("step_threshold", m->step_threshold);
  m->step_guard = f.getDouble("step_guard", m->step_guard);
  m->max_steps = static_cast<int>(std::clamp<long>(f.getInteger("max_steps", m->max_steps), -1, 1000));
  m->max_excluded = f.getDouble("max_excluded", m->max_excluded);
  m->block_false_alarm = f.getDouble("block_false_alarm", m->block_false_alarm);
}

void parseImu(const YamlField& f, ImuInput* imu) {
  f.requireMap();
  f.rejectUnknownKeys(kImuKeys);
  ImuInputSettings& c = imu->converter;
  if (f.has("mounting")) c.imu_to_body = parseRotation(f["mounting"]);
  c.period = f.getDouble("period", c.period);
  c.max_bridge = f.getDouble("max_bridge", c.max_bridge);
  c.fallback_rate_variance = f.getDouble("rate_variance", c.fallback_rate_variance);
  c.max_rate = f.getDouble("max_rate", c.max_rate);
  imu->accelerometer = f.getBool("accelerometer", imu->accelerometer);
  if (f.has("body_frame")) imu->body_frame = f["body_frame"].asString();
}

GyroInput parseGyroInput(const YamlField& f) {
  const std::string text = f.asString();
  if (text == "triad") return GyroInput::kTriad;
  if (text == "imu") return GyroInput::kImu;
  f.fail("'" + text + "' is not a gyro input: triad (TriadOutput) or imu (sensor_msgs/Imu)");
  return GyroInput::kTriad;
}

EstimatorChoice parseEstimator(const YamlField& f) {
  const std::string text = f.asString();
  if (text == "auto") return EstimatorChoice::kAuto;
  if (text == "still_base") return EstimatorChoice::kStillBase;
  if (text == "tracking") return EstimatorChoice::kTracking;
  f.fail("'" + text + "' is not an estimator: auto, still_base or tracking");
  return EstimatorChoice::kAuto;
}

// validate() names nested keys as the node's parameters ("level/roll"); a file's errors name them
// as YamlField does ("level.roll").
std::string dotted(std::string key) {
  std::replace(key.begin(), key.end(), '/', '.');
  return key;
}

}  // namespace

const std::vector<std::string>& AlignmentSettings::nodeKeys() { return kNodeKeys; }

std::vector<std::string> AlignmentSettings::keyPaths() {
  std::vector<std::string> keys = kScalarKeys;
  const std::vector<std::pair<const char*, const std::vector<std::string>*>> sections = {
      {"noise", &kNoiseKeys}, {"level", &kLevelKeys},   {"indexer", &kIndexerKeys},
      {"sweep", &kSweepKeys}, {"motion", &kMotionKeys}, {"imu", &kImuKeys}};
  for (const auto& section : sections) {
    for (const std::string& k : *section.second) keys.push_back(std::string(section.first) + "/" + k);
  }
  return keys;
}

AlignmentSettings AlignmentSettings::parse(const YamlField& root, const std::vector<std::string>& extra_keys,
                                           const std::string& base_directory) {
  root.requireMap();
  std::vector<std::string> allowed = kScalarKeys;
  allowed.insert(allowed.end(), kSections.begin(), kSections.end());
  allowed.insert(allowed.end(), extra_keys.begin(), extra_keys.end());
  root.rejectUnknownKeys(allowed);
  AlignmentSettings s;
  if (root.has("mode")) s.mode = parseAlignmentMode(root["mode"].asString(), root["mode"].path());
  s.latitude = root.getDouble("latitude", s.latitude);
  s.max_latitude = root.getDouble("max_latitude", s.max_latitude);
  s.duration = root.getDouble("duration", s.duration);
  s.single_gyro = root.getBool("single_gyro", s.single_gyro);
  s.max_earth_rate_error = root.getDouble("max_earth_rate_error", s.max_earth_rate_error);
  s.max_earth_sigmas = root.getDouble("max_earth_sigmas", s.max_earth_sigmas);
  s.max_estimator_sigmas = root.getDouble("max_estimator_sigmas", s.max_estimator_sigmas);
  if (root.has("estimator")) s.estimator = parseEstimator(root["estimator"]);
  s.max_condition = root.getDouble("max_condition", s.max_condition);
  s.noise_sources.angle_random_walk = s.noise_sources.rate_random_walk = "not given";
  s.noise_sources.residual_bias = s.noise_sources.residual_drift_harmonics = "not given";
  if (root.has("noise"))
    parseNoise(root["noise"], &s.noise, &s.noise_sources, &s.allan_file, &s.allan_tau0, base_directory);
  // After the Allan file, which names the white noise's source anew: the quantum adds to whichever.
  if (s.noise.angle_quantum > 0.0) s.noise_sources.angle_white_noise += " + the angle quantum's q^2/12";
  if (root.has("level")) parseLevel(root["level"], &s.level);
  if (root.has("indexer")) parseIndexer(root["indexer"], &s.indexer);
  if (root.has("sweep")) parseSweep(root["sweep"], &s.sweep);
  if (root.has("motion")) parseMotion(root["motion"], &s.motion);
  if (root.has("gyro_input")) s.gyro_input = parseGyroInput(root["gyro_input"]);
  if (root.has("imu")) parseImu(root["imu"], &s.imu);
  try {
    s.validate();
  } catch (const ConfigError& e) {
    const std::string key = root.path().empty() ? dotted(e.key()) : root.path() + "." + dotted(e.key());
    throw ConfigError(key, e.problem());
  }
  return s;
}

AlignmentSettings AlignmentSettings::load(const std::string& path) {
  const YAML::Node root = loadYamlFile(path, kMaxParameterFileBytes, "alignment settings file");
  try {
    const std::size_t slash = path.find_last_of('/');
    return parse(YamlField(root, ""), kNodeKeys, slash == std::string::npos ? "." : path.substr(0, slash));
  } catch (const ConfigError& e) {
    throw ConfigError(e.key(), e.problem() + " (in '" + path + "')");
  }
}

const char* toString(AlignmentMode mode) {
  switch (mode) {
    case AlignmentMode::kStatic:
      return "static";
    case AlignmentMode::kIndexed:
      return "indexed";
    case AlignmentMode::kSweep:
      return "sweep";
  }
  return "?";
}

AlignmentMode parseAlignmentMode(const std::string& text, const std::string& key) {
  if (text == "static") return AlignmentMode::kStatic;
  if (text == "indexed") return AlignmentMode::kIndexed;
  if (text == "sweep") return AlignmentMode::kSweep;
  throw ConfigError(key, "'" + text + "' is not a mode: static, indexed or sweep");
}

void GyroNoiseModel::validate(const std::string& prefix) const {
  if (!std::isfinite(angle_white_noise) || angle_white_noise == 0.0) {
    throw ConfigError(prefix + "angle_white_noise", "must be positive (rad per sample), or negative to measure it");
  }
  // Not given (NaN) passes here; requireComplete() refuses it where a budget needs it.
  auto check = [&](double v, const char* key, const char* unit) {
    if (!std::isnan(v)) requireFiniteAtLeast(v, 0.0, prefix + key, unit);
  };
  check(angle_random_walk, "angle_random_walk", "rad/sqrt(s)");
  check(rate_random_walk, "rate_random_walk", "rad/s/sqrt(s)");
  check(residual_bias, "residual_bias", "rad/s");
  check(residual_drift_harmonics, "residual_drift_harmonics", "rad/s");
  requireFiniteAtLeast(angle_quantum, 0.0, prefix + "angle_quantum", "rad");
}

void GyroNoiseModel::requireComplete(const std::string& prefix) const {
  validate(prefix);
  const char* allan =
      ": not given; measure it (hrg_bag allan --yaml on a still record, then noise/allan_file) or "
      "set it from the gyro's own Allan deviation (0 only if it shows none)";
  if (std::isnan(angle_random_walk))
    throw ConfigError(prefix + "angle_random_walk", std::string("rad/sqrt(s)") + allan);
  if (std::isnan(rate_random_walk))
    throw ConfigError(prefix + "rate_random_walk", std::string("rad/s/sqrt(s)") + allan);
  if (std::isnan(residual_bias)) {
    throw ConfigError(prefix + "residual_bias",
                      "rad/s: not given; the bias the calibration left, 1 sigma (the triad calibration's bias_std; "
                      "a triad file with a calibrated bias_std gives it)");
  }
  if (std::isnan(residual_drift_harmonics)) {
    throw ConfigError(prefix + "residual_drift_harmonics",
                      "rad/s: not given; the rms of D(theta) - D0 the calibration left, over |K0| (the axes' "
                      "calibration reports' D standard errors)");
  }
}

std::string NoiseSources::summary() const {
  return "white angle noise: " + angle_white_noise + "; angle random walk: " + angle_random_walk +
         "; rate random walk: " + rate_random_walk + "; residual bias: " + residual_bias +
         "; drift harmonics: " + residual_drift_harmonics;
}

GyroNoiseModel noiseFromAllan(const AllanResult& allan, const GyroNoiseModel& base, NoiseSources* sources,
                              const std::string& origin) {
  GyroNoiseModel out = base;
  NoiseSources ignored;
  NoiseSources& s = sources ? *sources : ignored;
  if (allan.angle_white_noise.identified) {
    out.angle_white_noise = allan.angle_white_noise.value;
    s.angle_white_noise = origin;
  }
  if (allan.angle_random_walk.identified) {
    out.angle_random_walk = allan.angle_random_walk.value;
    s.angle_random_walk = origin;
  }
  if (allan.rate_random_walk.identified) {
    out.rate_random_walk = allan.rate_random_walk.value;
    s.rate_random_walk = origin;
  }
  return out;
}

const char* toString(GyroInput input) { return input == GyroInput::kImu ? "imu" : "triad"; }

const char* toString(EstimatorChoice choice) {
  switch (choice) {
    case EstimatorChoice::kAuto:
      return "auto";
    case EstimatorChoice::kStillBase:
      return "still_base";
    case EstimatorChoice::kTracking:
      return "tracking";
  }
  return "?";
}

void LevelSettings::validate() const {
  if (source == LevelSource::kDeclared) {
    if (!std::isfinite(roll) || std::abs(roll) > 1.5) throw ConfigError("level/roll", "must be within +-1.5 rad");
    if (!std::isfinite(pitch) || std::abs(pitch) > 1.4) throw ConfigError("level/pitch", "must be within +-1.4 rad");
    if (!std::isnan(roll_sigma)) requireFiniteAtLeast(roll_sigma, 0.0, "level/roll_sigma", "rad");
    if (!std::isnan(pitch_sigma)) requireFiniteAtLeast(pitch_sigma, 0.0, "level/pitch_sigma", "rad");
  }
  const Eigen::Vector4d q = accelerometer_to_body.coeffs();
  if (!q.allFinite() || std::abs(q.norm() - 1.0) > 1e-6) {
    throw ConfigError("level/accelerometer_to_body", "must be a unit quaternion");
  }
  if (!std::isnan(accelerometer_bias_sigma)) {
    requireFiniteAtLeast(accelerometer_bias_sigma, 0.0, "level/accelerometer_bias_sigma", "m/s^2");
  }
  if (!std::isnan(accelerometer_mounting_sigma)) {
    requireFiniteAtLeast(accelerometer_mounting_sigma, 0.0, "level/accelerometer_mounting_sigma", "rad");
  }
  requirePositive(max_gravity_error, "level/max_gravity_error", "fraction of g");
}

void LevelSettings::requireComplete() const {
  validate();
  if (source == LevelSource::kDeclared) {
    if (std::isnan(roll_sigma) || std::isnan(pitch_sigma)) {
      throw ConfigError(std::isnan(roll_sigma) ? "level/roll_sigma" : "level/pitch_sigma",
                        "rad: not given; how well the declared level is known, 1 sigma (0 claims it exact)");
    }
    return;
  }
  if (std::isnan(accelerometer_bias_sigma)) {
    throw ConfigError(
        "level/accelerometer_bias_sigma",
        "m/s^2: not given; the accelerometer's residual bias, 1 sigma per axis (its calibration's, or its "
        "datasheet's bias stability)");
  }
  if (std::isnan(accelerometer_mounting_sigma)) {
    throw ConfigError("level/accelerometer_mounting_sigma",
                      "rad: not given; how well accelerometer_to_body is known, 1 sigma per axis (0 claims it exact)");
  }
}

void IndexerSettings::validate() const {
  const Eigen::Matrix3d r = body_to_platform;
  if (!r.allFinite() || (r.transpose() * r - Eigen::Matrix3d::Identity()).norm() > 1e-6 || r.determinant() < 0.0) {
    throw ConfigError("indexer/body_to_platform", "must be a rotation matrix");
  }
  if (!gyro_axis.allFinite() || std::abs(gyro_axis.norm() - 1.0) > 1e-6) {
    throw ConfigError("indexer/gyro_axis", "must be a unit vector");
  }
  requirePositive(rest_rate, "indexer/rest_rate", "rad/s");
  requireFiniteAtLeast(settle, 0.0, "indexer/settle", "s");
  requirePositive(position_tolerance, "indexer/position_tolerance", "rad");
  requirePositive(max_record_gap, "indexer/max_record_gap", "s");
  requireFiniteAtLeast(angle_sigma, 0.0, "indexer/angle_sigma", "rad");
}

void SweepSettings::validate() const {
  requireFiniteAtLeast(settle, 0.0, "sweep/settle", "s");
  for (int order : gain_orders) {
    if (order < 1 || order > 16) throw ConfigError("sweep/gain_orders", "orders must be in 1..16");
  }
  requirePositive(min_turns, "sweep/min_turns", "turns");
}

void MotionSettings::validate() const {
  requirePositive(block, "motion/block", "s");
  requirePositive(max_motion, "motion/max_motion", "rad/s");
  if (!std::isfinite(max_scatter) || max_scatter < 1.0) throw ConfigError("motion/max_scatter", "must be at least 1");
  requirePositive(step_threshold, "motion/step_threshold", "chi-square");
  requireFiniteAtLeast(step_guard, 0.0, "motion/step_guard", "s");
  if (step_guard > 60.0) throw ConfigError("motion/step_guard", "must be at most 60 s");
  if (max_steps < 0 || max_steps > 100) throw ConfigError("motion/max_steps", "must be in [0, 100]");
  if (!std::isfinite(max_excluded) || max_excluded < 0.0 || max_excluded > 0.9) {
    throw ConfigError("motion/max_excluded", "must be in [0, 0.9] of the window");
  }
  if (!(block_false_alarm >= 1e-9) || block_false_alarm > 0.1) {
    throw ConfigError("motion/block_false_alarm", "must be in [1e-9, 0.1]");
  }
}

void AlignmentSettings::validate() const {
  if (!validLatitude(latitude)) throw ConfigError("latitude", kLatitudeRule);
  if (!std::isfinite(max_latitude) || !(max_latitude > 0.0) || max_latitude >= 1.5707) {
    throw ConfigError("max_latitude", "must be in (0, pi/2) rad");
  }
  requirePositive(duration, "duration", "s");
  if (duration > 86400.0) throw ConfigError("duration", "must be at most a day (86400 s)");
  requirePositive(max_earth_rate_error, "max_earth_rate_error", "fraction");
  requirePositive(max_earth_sigmas, "max_earth_sigmas", "standard errors");
  requirePositive(max_estimator_sigmas, "max_estimator_sigmas", "standard errors");
  if (!std::isfinite(max_condition) || !(max_condition > 1.0)) throw ConfigError("max_condition", "must be above 1");
  if (single_gyro && mode != AlignmentMode::kIndexed) {
    throw ConfigError("single_gyro",
                      "one gyro alone finds north only on an indexer (mode indexed): "
                      "at rest it senses one horizontal component of the Earth's rate");
  }
  noise.validate();
  level.validate();
  indexer.validate();
  sweep.validate();
  motion.validate();
  imu.converter.validate("imu/");
  if (gyro_input == GyroInput::kImu && (single_gyro || mode == AlignmentMode::kSweep)) {
    throw ConfigError("gyro_input",
                      "imu: an IMU's three gyros align in mode static or indexed (not single_gyro, not sweep)");
  }
}

void AlignmentSettings::requireComplete() const {
  validate();
  noise.requireComplete();
  level.requireComplete();
}

}  // namespace core
}  // namespace hrg_gyro
