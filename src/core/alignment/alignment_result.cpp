#include "hrg_gyro/core/alignment/alignment_result.h"

#include <cmath>
#include <cstdio>
#include <sstream>

namespace hrg_gyro {
namespace core {
namespace {

constexpr double kDegrees = 180.0 / kPi;

std::string number(double v) {
  if (!std::isfinite(v)) return ".nan";
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%.12g", v);
  return buffer;
}

std::string quoted(const std::string& s) {
  std::string out = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') out += '\\';
    out += c;
  }
  return out + "\"";
}

std::string list(const std::vector<double>& values) {
  std::string out = "[";
  for (std::size_t i = 0; i < values.size(); ++i) out += (i ? ", " : "") + number(values[i]);
  return out + "]";
}

std::string matrix(const Eigen::Matrix3d& m) {
  std::string out = "[";
  for (int r = 0; r < 3; ++r) {
    out += r ? ", [" : "[";
    for (int c = 0; c < 3; ++c) out += (c ? ", " : "") + number(m(r, c));
    out += "]";
  }
  return out + "]";
}

}  // namespace

std::string AlignmentResult::summary() const {
  char buffer[512];
  if (!accepted) {
    std::snprintf(buffer, sizeof buffer, "alignment refused (%s): %s", gate.c_str(), reason.c_str());
    return buffer;
  }
  std::snprintf(buffer, sizeof buffer,
                "true heading %.4f deg +- %.4f deg (1 sigma), roll %.4f deg, pitch %.4f deg; %s%s, %s, %.1f s; "
                "mrad: noise %.3f, bias %.3f, drift harmonics %.3f, bias walk %.3f, level %.3f",
                heading, heading_sigma, attitude.roll * kDegrees, attitude.pitch * kDegrees, toString(mode),
                single_gyro ? " (one gyro)" : "", estimator.c_str(), seconds, 1e3 * budget.noise,
                1e3 * budget.residual_bias, 1e3 * budget.drift_harmonics, 1e3 * budget.bias_random_walk,
                1e3 * budget.level);
  return buffer;
}

namespace {

// What the estimator chose and why, what the base did, where the noise terms came from, and the
// checks against the Earth: the part of the result a moving base fills in.
void emitEstimatorAndEarthChecks(const AlignmentResult& r, std::ostringstream& y) {
  y << "estimator: " << quoted(r.estimator) << "\n";
  y << "estimator_reason: " << quoted(r.estimator_reason) << "\n";
  y << "noise_sources: " << quoted(r.noise_sources) << "\n";
  y << "low_frequency_scatter: " << number(r.low_frequency_scatter) << "\n";
  y << "low_frequency_limit: " << number(r.low_frequency_limit) << "\n";
  y << "excluded_s: " << number(r.excluded_seconds) << "\n";
  y << "tracking: {heading_deg: " << number(r.tracking_heading)
    << ", heading_sigma_deg: " << number(r.tracking_heading_sigma)
    << ", difference_sigmas: " << number(r.estimator_difference) << ", velocity_white_m_s: " << number(r.velocity_white)
    << ", velocity_random_walk_m_s_sqrt_s: " << number(r.velocity_random_walk) << "}\n";
  y << "base_steps:";
  for (const BaseStepRecord& b : r.base_steps) {
    y << "\n  - {time_s: " << number(b.time) << ", rotation_rad: [" << number(b.rotation.x()) << ", "
      << number(b.rotation.y()) << ", " << number(b.rotation.z()) << "], chi_square: " << number(b.chi_square) << "}";
  }
  y << (r.base_steps.empty() ? " []\n" : "\n");
  y << "earth_checks:";
  for (const EarthCheck& c : r.earth_checks) {
    y << "\n  - {name: " << c.name << ", measured: " << number(c.measured) << ", expected: " << number(c.expected)
      << ", sigma: " << number(c.sigma) << ", passed: " << (c.passed ? "true" : "false") << "}";
  }
  y << (r.earth_checks.empty() ? " []\n" : "\n");
}

}  // namespace

std::string emitAlignmentResult(const AlignmentResult& r) {
  std::ostringstream y;
  y << "# hrg_gyro alignment from the Earth's rate. Frames: ENU local level (x East, y North, z Up);\n"
    << "# orientation = rotation " << r.frame << " -> ENU (x, y, z, w); heading clockwise from true North.\n";
  y << "accepted: " << (r.accepted ? "true" : "false") << "\n";
  y << "gate: " << quoted(r.gate) << "\n";
  y << "reason: " << quoted(r.reason) << "\n";
  y << "notes: [";
  for (std::size_t i = 0; i < r.notes.size(); ++i) y << (i ? ", " : "") << quoted(r.notes[i]);
  y << "]\n";
  y << "mode: " << toString(r.mode) << "\n";
  y << "single_gyro: " << (r.single_gyro ? "true" : "false") << "\n";
  y << "frame: " << r.frame << "\n";
  y << "window: {start_ns: " << r.start << ", end_ns: " << r.end << ", last_sample_ns: " << r.last_sample
    << ", seconds: " << number(r.seconds) << ", samples: " << r.samples << "}\n";
  y << "heading_deg: " << number(r.heading) << "\n";
  y << "heading_sigma_deg: " << number(r.heading_sigma) << "\n";
  y << "attitude_rad: {roll: " << number(r.attitude.roll) << ", pitch: " << number(r.attitude.pitch)
    << ", yaw: " << number(r.attitude.yaw) << "}\n";
  const Eigen::Quaterniond& q = r.orientation;
  y << "orientation: [" << number(q.x()) << ", " << number(q.y()) << ", " << number(q.z()) << ", " << number(q.w())
    << "]\n";
  y << "covariance_rpy_rad2: " << matrix(r.covariance_rpy) << "\n";
  y << "covariance_enu_rad2: " << matrix(r.covariance_enu) << "\n";
  const Eigen::Quaterniond& b = r.body_orientation;
  y << "body_orientation: [" << number(b.x()) << ", " << number(b.y()) << ", " << number(b.z()) << ", " << number(b.w())
    << "]\n";
  y << "earth_rate: {levelled_rad_s: [" << number(r.levelled_rate.x()) << ", " << number(r.levelled_rate.y()) << ", "
    << number(r.levelled_rate.z()) << "], horizontal_rad_s: " << number(r.horizontal_rate)
    << ", horizontal_std_rad_s: " << number(r.horizontal_rate_std)
    << ", expected_horizontal_rad_s: " << number(r.budget.horizontal_earth_rate) << "}\n";
  const HeadingErrorBudget& e = r.budget;
  y << "budget_rad:  # heading, 1 sigma by source\n"
    << "  white_angle_noise: " << number(e.white_angle_noise) << "\n"
    << "  angle_random_walk: " << number(e.angle_random_walk) << "\n"
    << "  noise: " << number(e.noise) << "\n"
    << "  residual_bias: " << number(e.residual_bias) << "\n"
    << "  drift_harmonics: " << number(e.drift_harmonics) << "\n"
    << "  bias_random_walk: " << number(e.bias_random_walk) << "\n"
    << "  level: " << number(e.level) << "\n"
    << "  indexer: " << number(e.indexer) << "\n"
    << "  total: " << number(e.total) << "\n"
    << "  latitude_rad: " << number(e.latitude) << "\n"
    << "  max_latitude_rad: " << number(e.max_latitude) << "\n";
  y << "white_noise_rad: " << list(r.white_noise) << "\n";
  y << "scatter: " << number(r.scatter) << "\n";
  y << "worst_motion_rad_s: " << number(r.worst_motion) << "\n";
  y << "accelerometer_gravity_m_s2: " << number(r.accelerometer_gravity) << "\n";
  emitEstimatorAndEarthChecks(r, y);
  y << "segments:\n";
  for (const AlignmentSegment& s : r.segments) {
    y << "  - {start_s: " << number(s.start) << ", end_s: " << number(s.end)
      << ", indexer_angle_rad: " << number(s.indexer_angle) << ", commanded_rate_rad_s: " << number(s.commanded_rate)
      << ", residual_rate_rad_s: " << list(s.residual_rate)
      << ", residual_rate_std_rad_s: " << list(s.residual_rate_std) << ", rms_rad: " << list(s.rms)
      << ", predicted_rms_rad: " << list(s.predicted_rms) << "}\n";
  }
  if (r.segments.empty()) y << "  []\n";
  return y.str();
}

}  // namespace core
}  // namespace hrg_gyro
