#include "hrg_gyro/core/alignment/alignment_settings.h"

#include <cmath>

#include "hrg_gyro/core/common/yaml_field.h"

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

}  // namespace

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
  requireFiniteAtLeast(angle_random_walk, 0.0, prefix + "angle_random_walk", "rad/sqrt(s)");
  requireFiniteAtLeast(rate_random_walk, 0.0, prefix + "rate_random_walk", "rad/s/sqrt(s)");
  requireFiniteAtLeast(residual_bias, 0.0, prefix + "residual_bias", "rad/s");
  requireFiniteAtLeast(residual_drift_harmonics, 0.0, prefix + "residual_drift_harmonics", "rad/s");
}

GyroNoiseModel noiseFromAllan(const AllanResult& allan, const GyroNoiseModel& base) {
  GyroNoiseModel out = base;
  if (allan.angle_white_noise.identified) out.angle_white_noise = allan.angle_white_noise.value;
  if (allan.angle_random_walk.identified) out.angle_random_walk = allan.angle_random_walk.value;
  if (allan.rate_random_walk.identified) out.rate_random_walk = allan.rate_random_walk.value;
  return out;
}

void LevelSettings::validate() const {
  if (source == LevelSource::kDeclared) {
    if (!std::isfinite(roll) || std::abs(roll) > 1.5) throw ConfigError("level/roll", "must be within +-1.5 rad");
    if (!std::isfinite(pitch) || std::abs(pitch) > 1.4) throw ConfigError("level/pitch", "must be within +-1.4 rad");
    requireFiniteAtLeast(roll_sigma, 0.0, "level/roll_sigma", "rad");
    requireFiniteAtLeast(pitch_sigma, 0.0, "level/pitch_sigma", "rad");
  }
  const Eigen::Vector4d q = accelerometer_to_body.coeffs();
  if (!q.allFinite() || std::abs(q.norm() - 1.0) > 1e-6) {
    throw ConfigError("level/accelerometer_to_body", "must be a unit quaternion");
  }
  requireFiniteAtLeast(accelerometer_bias_sigma, 0.0, "level/accelerometer_bias_sigma", "m/s^2");
  requirePositive(max_gravity_error, "level/max_gravity_error", "fraction of g");
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
}

void AlignmentSettings::validate() const {
  if (!std::isfinite(latitude) || std::abs(latitude) > 0.5 * 3.14159265358979323846) {
    throw ConfigError("latitude", "must be given, in [-pi/2, pi/2] rad");
  }
  if (!std::isfinite(max_latitude) || !(max_latitude > 0.0) || max_latitude >= 1.5707) {
    throw ConfigError("max_latitude", "must be in (0, pi/2) rad");
  }
  requirePositive(duration, "duration", "s");
  if (duration > 86400.0) throw ConfigError("duration", "must be at most a day (86400 s)");
  requirePositive(max_earth_rate_error, "max_earth_rate_error", "fraction");
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
}

}  // namespace core
}  // namespace hrg_gyro
