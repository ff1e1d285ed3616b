// What three gyros share when they are one IMU: the matrix from their compensated rates to the body
// frame's, a body-frame bias, the body frame's name, and where the numbers came from. Each axis keeps
// its own parameter file (K(theta), D(theta), P: gyro_parameters.h); the triad file adds this.
//
// The equation, in SI units and REP-103 frames (right-handed, rad, rad/s):
//
//   omega_body = M omega_axis - bias
//
// omega_axis = (r_1, r_2, r_3): each axis's compensated inertial rate dalpha/dt (rad/s about its own
// sensitive axis, counter-clockwise positive seen from its tip), in the order of `axes`; omega_body:
// the inertial angular velocity of the body frame `frame_id`, in that frame. The axes measure
// omega_axis = A (omega_body + bias) with A = M^-1: row i of A is axis i's sensitive direction in
// the body frame times its residual scale. A is I plus small terms: its off-diagonal entries are the
// axes' six misalignment angles (A_ij: the tilt of axis i towards body axis j, rad) in full form, not
// triangular: the body frame is the fixture's (its mounting faces), tied to no axis. Its diagonal is
// 1 plus each axis's residual scale (what the per-axis K(theta) leaves, zero when K was calibrated on
// the same fixture). Covariances map the same way: Sigma_body = M diag(sigma_i^2) M^T.
//
// For an angle increment over dt: delta_angle_body = M dalpha - bias dt. No ROS.
#pragma once

#include <Eigen/Core>
#include <array>
#include <string>

#include "hrg_gyro/core/common/yaml_field.h"
#include "hrg_gyro/core/model/gyro_parameters.h"

namespace hrg_gyro {
namespace core {

struct TriadParameters {
  /// The three axes, in the order of M's columns: each axis's name, which is also the namespace of
  /// its processor (and of its parameter file) in a launch; distinct, each isValidAxisName().
  std::array<std::string, 3> axes{{"x", "y", "z"}};
  std::string frame_id = "imu_link";                           ///< the body frame
  Eigen::Matrix3d axis_to_body = Eigen::Matrix3d::Identity();  ///< M, dimensionless
  Eigen::Vector3d bias = Eigen::Vector3d::Zero();              ///< rad/s, body frame
  /// Standard errors of M's entries and of the bias (zero: not known, e.g. a nominal triad).
  Eigen::Matrix3d axis_to_body_std = Eigen::Matrix3d::Zero();
  Eigen::Vector3d bias_std = Eigen::Vector3d::Zero();
  CalibrationProvenance calibration;

  /// A = M^-1: the axes' sensitive directions (rows) in the body frame, with their residual scales.
  Eigen::Matrix3d bodyToAxis() const;
  bool operator==(const TriadParameters& o) const;
  bool operator!=(const TriadParameters& o) const { return !(*this == o); }
};

/// Largest |M_ij - I_ij| accepted: beyond it the axes are not the nominal body axes (a wrong axis
/// order or sign, a unit slip), which a calibration refuses to write and the loader to read.
constexpr double kMaxTriadMisalignment = 0.1;

/// Whether `name` can name an axis: the triad node makes topics (`<axis>/output`) and a launch
/// namespaces from it, so it must be one ROS graph name component: an ASCII letter first, then
/// letters, digits or '_' (no '/', '~', '.', ':', blank or control character).
bool isValidAxisName(const std::string& name);
/// A frame id as tf2 takes it: not empty, no leading '/', no blanks or control characters.
bool isValidFrameId(const std::string& id);

/// Validates and converts a parsed triad document. Throws ConfigError naming the key.
TriadParameters parseTriadParameters(const YAML::Node& root);
/// Reads and validates a triad file (regular file, bounded size, every bad key named).
TriadParameters loadTriadFile(const std::string& path);
/// The file text, with the equation and a comment on every key; the misalignment angles and the
/// residual scales (from A = M^-1) as comments for the reader.
std::string emitTriadParameters(const TriadParameters& triad);
/// Atomic, validated save; the replaced file kept as <file>.bak when `keep_backup`.
void saveTriadFile(const std::string& path, const TriadParameters& triad, bool keep_backup = true);

}  // namespace core
}  // namespace hrg_gyro
