#include "hrg_gyro/core/alignment/earth_rate_heading.h"

#include <algorithm>
#include <cmath>

#include "hrg_gyro/core/model/earth_rate.h"

namespace hrg_gyro {
namespace core {

HeadingSolution solveHeading(const EarthRateMeasurement& m, const LevelMeasurement& level, double latitude) {
  HeadingSolution out;
  const double h = horizontalEarthRate(latitude);
  const Eigen::Matrix3d l = levelRotation(level.roll, level.pitch);
  const Eigen::Vector3d wl = l * m.rate;
  const double yaw = std::atan2(wl.x(), wl.y());
  out.levelled_rate = wl;
  out.horizontal_rate = std::hypot(wl.x(), wl.y());
  out.attitude.roll = level.roll;
  out.attitude.pitch = level.pitch;
  out.attitude.yaw = yaw;
  out.orientation = orientationFromEuler(out.attitude);

  // d yaw = a^T (L dw + dL w) about the truth, whose horizontal rate is h.
  const Eigen::Vector3d a = Eigen::Vector3d(std::cos(yaw), -std::sin(yaw), 0.0) / h;
  const Eigen::RowVector3d by_rate = a.transpose() * l;
  const Eigen::RowVector2d by_level(a.dot(levelRotationByRoll(level.roll, level.pitch) * m.rate),
                                    a.dot(levelRotationByPitch(level.roll, level.pitch) * m.rate));
  auto quadratic = [&](const Eigen::Matrix3d& p) { return std::max(by_rate.dot(p * by_rate.transpose()), 0.0); };
  auto sigma = [&](const Eigen::Matrix3d& p) { return std::sqrt(quadratic(p)); };
  HeadingErrorBudget& b = out.budget;
  b.white_angle_noise = sigma(m.white);
  b.angle_random_walk = sigma(m.angle_random_walk);
  b.noise = std::hypot(b.white_angle_noise, b.angle_random_walk);
  b.residual_bias = sigma(m.residual_bias);
  b.drift_harmonics = sigma(m.drift_harmonics);
  b.bias_random_walk = sigma(m.rate_random_walk);
  b.indexer = sigma(m.indexer);
  b.level = std::sqrt(std::max(by_level.dot(level.covariance * by_level.transpose()), 0.0));
  const double yaw_variance = quadratic(m.covariance()) + b.level * b.level;
  b.total = std::sqrt(std::max(yaw_variance, 0.0));
  b.horizontal_earth_rate = h;
  b.latitude = latitude;

  out.covariance_rpy.topLeftCorner<2, 2>() = level.covariance;
  const Eigen::Vector2d cross = level.covariance * by_level.transpose();
  out.covariance_rpy.block<2, 1>(0, 2) = cross;
  out.covariance_rpy.block<1, 2>(2, 0) = cross.transpose();
  out.covariance_rpy(2, 2) = yaw_variance;
  out.covariance_enu = enuCovarianceFromEuler(out.attitude, out.covariance_rpy);

  // A body bias raises the measured yaw by by_rate * bias_transfer * b; the ENU error is the truth
  // less the estimate, about z (E's yaw column).
  out.bias_to_attitude.setZero();
  out.bias_to_attitude.row(2) = -(by_rate * m.bias_transfer);

  const Eigen::RowVector3d radial = Eigen::RowVector3d(std::sin(yaw), std::cos(yaw), 0.0) * l;
  out.horizontal_rate_std = std::sqrt(std::max(radial.dot(m.covariance() * radial.transpose()), 0.0));
  return out;
}

}  // namespace core
}  // namespace hrg_gyro
