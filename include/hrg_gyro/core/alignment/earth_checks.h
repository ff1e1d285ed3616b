// The checks only the Earth can pass: a measured Earth's rate w and a measured up direction u (unit,
// from the accelerometer or the declared level) must agree with the declared latitude:
//
//   length      |w| = Omega                                  (a gross bias, a scale error, a turning base)
//   vertical    w . u = Omega sin(lat)                       (a wrong latitude or its sign, an accelerometer
//                                                             that reports gravity, -g up, instead of the
//                                                             specific force, a gross vertical bias)
//   angle       the angle between w and u = 90 deg - lat     (an axis of the accelerometer reversed or
//                                                             swapped, a mounting far from the one set)
//
// each within `sigmas` of its standard error, propagated from w's and u's covariances (first order).
// What no check can see: a tilt of u about the North (the one that turns the heading by e tan(lat))
// leaves w . u and the angle unchanged to first order, so a small level error passes and is budgeted
// instead; a horizontal gyro bias within the length's sigma passes likewise. No ROS.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

namespace hrg_gyro {
namespace core {

struct EarthCheck {
  std::string name;       ///< "length", "vertical", "angle"
  double measured = 0.0;  ///< rad/s (length, vertical) or rad (angle)
  double expected = 0.0;
  double sigma = 0.0;  ///< the difference's standard error
  bool passed = true;
  /// One line: the quantity, measured, expected, sigma and what a failure means.
  std::string describe() const;
};

/// The three checks. `rate_covariance` and `up_covariance` are (rad/s)^2 and 1 (of u's components);
/// `vertical_measured` false (the indexed mode imposes w's vertical part) leaves out the vertical and
/// angle checks.
std::vector<EarthCheck> checkAgainstTheEarth(const Eigen::Vector3d& rate, const Eigen::Matrix3d& rate_covariance,
                                             const Eigen::Vector3d& up, const Eigen::Matrix3d& up_covariance,
                                             double latitude, double sigmas, bool vertical_measured = true);

/// The first check that failed, if any.
std::optional<EarthCheck> firstFailed(const std::vector<EarthCheck>& checks);

/// The covariance of the unit up direction in a frame of roll and pitch (REP-103 angles) with the
/// covariance of (roll, pitch).
Eigen::Matrix3d upCovarianceFromLevel(double roll, double pitch, const Eigen::Matrix2d& level_covariance);

}  // namespace core
}  // namespace hrg_gyro
