// What three gyros share when they are one IMU: the matrix from their compensated rates to the body
// frame's, a body-frame bias, the body frame's name, the axes' names, and where the numbers came
// from. Each axis keeps its own parameter file (K(theta), D(theta), P: gyro_parameters.h); the triad
// file (triad_file.h) adds this set:
//
//   omega_body = M omega_axis - bias          (rad/s; M: axis_to_body_matrix.h says what it holds)
//
// For an angle increment over dt: delta_angle_body = M dalpha - bias dt. No ROS.
#pragma once

#include <Eigen/Core>
#include <array>
#include <string>

#include "hrg_gyro/core/model/axis_to_body_matrix.h"
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

/// Whether `name` can name an axis: the triad node makes topics (`<axis>/output`) and a launch
/// namespaces from it, so it must be one ROS graph name component: an ASCII letter first, then
/// letters, digits or '_' (no '/', '~', '.', ':', blank or control character).
bool isValidAxisName(const std::string& name);
/// A frame id as tf2 takes it: not empty, no leading '/', no blanks or control characters.
bool isValidFrameId(const std::string& id);

}  // namespace core
}  // namespace hrg_gyro
