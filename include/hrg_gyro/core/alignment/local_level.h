// The frames and sign conventions of north-finding, in one place (REP-103, REP-105, REP-145).
//
//   Local level (n): ENU, x East, y North, z Up, fixed to the Earth at the site. The vehicle's own
//                    travel over the Earth is not modelled anywhere in alignment/: the site stays put.
//   Body (b):        the triad's frame (x forward, y left, z up for a base_link-like mount), or the
//                    indexer's zero frame in the indexed mode.
//   Orientation:     the rotation body -> ENU, C = Rz(yaw) Ry(pitch) Rx(roll) (v_n = C v_b), as a
//                    quaternion; roll, pitch, yaw the REP-103 fixed-axis angles.
//   Yaw:             in ENU, counter-clockwise from East (yaw 0: body x points East).
//   True heading:    what a navigator reads, clockwise from North in degrees:
//                    heading = 90 deg - yaw, wrapped to [0, 360).
//   Earth's rate:    Omega_n = Omega (0, cos(lat), sin(lat)), Omega = kEarthRotationRate (7.292115e-5
//                    rad/s), lat the geodetic latitude (north positive).
//   Gravity:         an accelerometer at rest measures the specific force f_n = (0, 0, +g) (REP-145
//                    linear_acceleration), so in the body f_b = C^T (0, 0, g):
//                    f_b = g (-sin(pitch), cos(pitch) sin(roll), cos(pitch) cos(roll)).
//
// Levelled frame (l): the body turned by its roll and pitch only, v_l = Ry(pitch) Rx(roll) v_b; it
// differs from ENU by the yaw alone, so the Earth's rate there is Rz(-yaw) Omega_n =
// (h sin(yaw), h cos(yaw), v) with h = Omega cos(lat) (horizontal) and v = Omega sin(lat) (vertical):
//
//   yaw = atan2(w_l.x, w_l.y)
//
// An attitude error is a small rotation delta in ENU: C_true = (I + [delta x]) C. Its x and y are the
// tilts about East and North, its z the yaw (heading) error. Its covariance maps to that of (roll,
// pitch, yaw) through E, the matrix whose columns are the ENU axes of the three angles
// (delta = E d(roll, pitch, yaw)). No ROS.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "hrg_gyro/core/model/earth_rate.h"  // the Earth's rate in ENU and its parts

namespace hrg_gyro {
namespace core {

/// m/s^2, the standard gravity (the magnitude an accelerometer at rest is checked against).
constexpr double kStandardGravity = 9.80665;

struct EulerAngles {
  double roll = 0.0, pitch = 0.0, yaw = 0.0;  ///< rad, C = Rz(yaw) Ry(pitch) Rx(roll)
};

/// Ry(pitch) Rx(roll): body -> levelled frame.
Eigen::Matrix3d levelRotation(double roll, double pitch);
/// Its derivatives with respect to roll and to pitch.
Eigen::Matrix3d levelRotationByRoll(double roll, double pitch);
Eigen::Matrix3d levelRotationByPitch(double roll, double pitch);

/// Rz(yaw) Ry(pitch) Rx(roll) as a unit quaternion (body -> ENU).
Eigen::Quaterniond orientationFromEuler(const EulerAngles& angles);
/// The angles of an orientation (yaw in (-pi, pi], pitch in [-pi/2, pi/2]).
EulerAngles eulerFromOrientation(const Eigen::Quaterniond& orientation);

/// True heading, degrees clockwise from North in [0, 360), of a yaw (rad, ENU counter-clockwise from East).
double trueHeadingDegrees(double yaw);
/// The yaw (rad, in (-pi, pi]) of a true heading in degrees.
double yawFromTrueHeading(double heading_degrees);

/// Roll and pitch of a specific force measured at rest in the body frame (yaw left 0).
EulerAngles levelFromSpecificForce(const Eigen::Vector3d& f_body);
/// d(roll, pitch) / d f_body (2 x 3), at f_body.
Eigen::Matrix<double, 2, 3> levelJacobian(const Eigen::Vector3d& f_body);

/// E: delta (ENU small rotation) = E d(roll, pitch, yaw). Singular at pitch = +-pi/2.
Eigen::Matrix3d eulerToEnuRotation(const EulerAngles& angles);
/// The covariance of (roll, pitch, yaw) from that of the ENU small rotation: E^-1 P E^-T.
Eigen::Matrix3d eulerCovarianceFromEnu(const EulerAngles& angles, const Eigen::Matrix3d& enu_covariance);
/// The other way: E P E^T.
Eigen::Matrix3d enuCovarianceFromEuler(const EulerAngles& angles, const Eigen::Matrix3d& euler_covariance);

/// The rotation exp([v x]) of a rotation vector v (rad), exact for any size.
Eigen::Quaterniond rotationVectorToQuaternion(const Eigen::Vector3d& v);

}  // namespace core
}  // namespace hrg_gyro
