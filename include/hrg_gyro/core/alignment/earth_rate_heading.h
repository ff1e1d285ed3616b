// From the Earth's rate measured in a frame and that frame's level to its attitude, with the heading's
// error budget: the last step of every alignment mode (frames and signs: local_level.h).
//
// With w the Earth's rate measured in the frame (body, or the indexer's zero frame) and (roll, pitch)
// its level, w_l = Ry(pitch) Rx(roll) w and
//
//   yaw = atan2(w_l.x, w_l.y),      heading = 90 deg - yaw
//
// Linearised about the truth (w_l horizontal of length h = Omega cos(lat)):
//   d yaw = a^T (L dw + dL w),      a = (cos yaw, -sin yaw, 0) / h
// so every error of w enters divided by the horizontal Earth rate: a rate error b across the
// horizontal Earth rate costs b / (Omega cos(lat)) rad of heading (1e-8 rad/s at 0.9 rad: 0.22 mrad),
// and a tilt error e about the North axis (the East axis tipped up or down) tips the vertical Earth
// rate Omega sin(lat) into the East component, across the horizontal Earth rate: e tan(lat) rad of
// heading (tan(0.9) = 1.26). A tilt about East tips it into the North component, along the horizontal
// rate: it changes the rate's length, not its direction, and costs nothing to first order. The latitude enters only
// through h (and the vertical rate v that the indexed mode puts in for the component it does not measure); close to the
// poles h vanishes and the errors grow as 1 / cos(lat): above max_latitude the alignment is refused.
//
// The covariance of (roll, pitch, yaw) is that of the level, propagated, beside the sum of the yaw
// terms; the level and the gyros' errors are independent. No ROS.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "hrg_gyro/core/alignment/local_level.h"

namespace hrg_gyro {
namespace core {

/// The Earth's rate measured in a frame, with its covariance by source (all 3 x 3, (rad/s)^2).
struct EarthRateMeasurement {
  Eigen::Vector3d rate = Eigen::Vector3d::Zero();               ///< rad/s
  Eigen::Matrix3d white = Eigen::Matrix3d::Zero();              ///< white angle noise
  Eigen::Matrix3d angle_random_walk = Eigen::Matrix3d::Zero();  ///< N
  Eigen::Matrix3d rate_random_walk = Eigen::Matrix3d::Zero();   ///< K over the window
  Eigen::Matrix3d residual_bias = Eigen::Matrix3d::Zero();      ///< the calibration's bias
  Eigen::Matrix3d drift_harmonics = Eigen::Matrix3d::Zero();    ///< D(theta)'s residual harmonics
  Eigen::Matrix3d indexer = Eigen::Matrix3d::Zero();            ///< indexer angle errors
  /// d rate / d (a constant bias of the triad's body axes), dimensionless.
  Eigen::Matrix3d bias_transfer = Eigen::Matrix3d::Zero();
  Eigen::Matrix3d covariance() const {
    return white + angle_random_walk + rate_random_walk + residual_bias + drift_harmonics + indexer;
  }
};

struct LevelMeasurement {
  double roll = 0.0, pitch = 0.0;                        ///< rad
  Eigen::Matrix2d covariance = Eigen::Matrix2d::Zero();  ///< rad^2, of (roll, pitch)
};

/// The heading's standard errors by source, rad (1 sigma), and what they are divided by.
struct HeadingErrorBudget {
  double white_angle_noise = 0.0;             ///< falls as T^-3/2
  double angle_random_walk = 0.0;             ///< falls as T^-1/2
  double noise = 0.0;                         ///< the two together: what a longer window lowers
  double residual_bias = 0.0;                 ///< the calibration's bias: a floor (static, sweep); cancels indexed
  double drift_harmonics = 0.0;               ///< D(theta) residual: in full at rest, averaged by a sweep
  double bias_random_walk = 0.0;              ///< grows as T^1/2
  double level = 0.0;                         ///< the tilt about North, times tan(lat)
  double indexer = 0.0;                       ///< the indexer's angle errors
  double total = 0.0;                         ///< root sum of squares
  double horizontal_earth_rate = 0.0;         ///< rad/s, Omega cos(lat): every gyro error is divided by it
  double latitude = 0.0, max_latitude = 0.0;  ///< rad
};

struct HeadingSolution {
  EulerAngles attitude;                                             ///< of the frame
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();  ///< frame -> ENU
  Eigen::Matrix3d covariance_rpy = Eigen::Matrix3d::Zero();         ///< rad^2, (roll, pitch, yaw)
  Eigen::Matrix3d covariance_enu = Eigen::Matrix3d::Zero();         ///< rad^2, ENU small rotation
  /// d delta / d (constant body bias): the attitude error (ENU small rotation, C_true = (I + [delta x])
  /// C) a bias of the triad's body axes leaves, rad per rad/s.
  Eigen::Matrix3d bias_to_attitude = Eigen::Matrix3d::Zero();
  Eigen::Vector3d levelled_rate = Eigen::Vector3d::Zero();  ///< w_l, rad/s
  double horizontal_rate = 0.0;                             ///< |w_l.xy|, rad/s: the Earth's h if all is well
  double horizontal_rate_std = 0.0;                         ///< its standard error, rad/s
  HeadingErrorBudget budget;
};

/// Levels `rate` by `level` and finds the yaw; `latitude` (rad) gives h and the budget's divisor.
HeadingSolution solveHeading(const EarthRateMeasurement& rate, const LevelMeasurement& level, double latitude);

}  // namespace core
}  // namespace hrg_gyro
