#include "hrg_gyro/core/alignment/local_level.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

#include "hrg_gyro/core/common/units.h"

namespace hrg_gyro {
namespace core {
namespace {

Eigen::Matrix3d rotX(double a) {
  const double c = std::cos(a), s = std::sin(a);
  Eigen::Matrix3d r;
  r << 1, 0, 0, 0, c, -s, 0, s, c;
  return r;
}
Eigen::Matrix3d rotY(double a) {
  const double c = std::cos(a), s = std::sin(a);
  Eigen::Matrix3d r;
  r << c, 0, s, 0, 1, 0, -s, 0, c;
  return r;
}
Eigen::Matrix3d rotZ(double a) {
  const double c = std::cos(a), s = std::sin(a);
  Eigen::Matrix3d r;
  r << c, -s, 0, s, c, 0, 0, 0, 1;
  return r;
}
// d/da of the rotations above.
Eigen::Matrix3d rotXDerivative(double a) {
  const double c = std::cos(a), s = std::sin(a);
  Eigen::Matrix3d r;
  r << 0, 0, 0, 0, -s, -c, 0, c, -s;
  return r;
}
Eigen::Matrix3d rotYDerivative(double a) {
  const double c = std::cos(a), s = std::sin(a);
  Eigen::Matrix3d r;
  r << -s, 0, c, 0, 0, 0, -c, 0, -s;
  return r;
}

}  // namespace

Eigen::Matrix3d levelRotation(double roll, double pitch) { return rotY(pitch) * rotX(roll); }
Eigen::Matrix3d levelRotationByRoll(double roll, double pitch) { return rotY(pitch) * rotXDerivative(roll); }
Eigen::Matrix3d levelRotationByPitch(double roll, double pitch) { return rotYDerivative(pitch) * rotX(roll); }

Eigen::Quaterniond orientationFromEuler(const EulerAngles& a) {
  Eigen::Quaterniond q(rotZ(a.yaw) * rotY(a.pitch) * rotX(a.roll));
  q.normalize();
  return q;
}

EulerAngles eulerFromOrientation(const Eigen::Quaterniond& orientation) {
  const Eigen::Matrix3d r = orientation.normalized().toRotationMatrix();
  EulerAngles a;
  a.pitch = std::asin(std::clamp(-r(2, 0), -1.0, 1.0));
  a.roll = std::atan2(r(2, 1), r(2, 2));
  a.yaw = std::atan2(r(1, 0), r(0, 0));
  return a;
}

double trueHeadingDegrees(double yaw) { return positiveModulo(90.0 - yaw * 180.0 / kPi, 360.0); }

double yawFromTrueHeading(double heading_degrees) { return wrapToPi((90.0 - heading_degrees) * kPi / 180.0); }

EulerAngles levelFromSpecificForce(const Eigen::Vector3d& f) {
  EulerAngles a;
  a.roll = std::atan2(f.y(), f.z());
  a.pitch = std::atan2(-f.x(), std::hypot(f.y(), f.z()));
  return a;
}

Eigen::Matrix<double, 2, 3> levelJacobian(const Eigen::Vector3d& f) {
  const double yz2 = f.y() * f.y() + f.z() * f.z(), rho = std::sqrt(yz2), all2 = yz2 + f.x() * f.x();
  Eigen::Matrix<double, 2, 3> j;
  j << 0.0, f.z() / yz2, -f.y() / yz2,                                          // roll = atan2(f_y, f_z)
      -rho / all2, f.x() * f.y() / (rho * all2), f.x() * f.z() / (rho * all2);  // pitch = atan2(-f_x, rho)
  return j;
}

Eigen::Matrix3d eulerToEnuRotation(const EulerAngles& a) {
  Eigen::Matrix3d e;
  e.col(0) = rotZ(a.yaw) * rotY(a.pitch) * Eigen::Vector3d::UnitX();
  e.col(1) = rotZ(a.yaw) * Eigen::Vector3d::UnitY();
  e.col(2) = Eigen::Vector3d::UnitZ();
  return e;
}

Eigen::Matrix3d eulerCovarianceFromEnu(const EulerAngles& angles, const Eigen::Matrix3d& enu_covariance) {
  const Eigen::Matrix3d inverse = eulerToEnuRotation(angles).inverse();
  const Eigen::Matrix3d p = inverse * enu_covariance * inverse.transpose();
  return 0.5 * (p + p.transpose());
}

Eigen::Matrix3d enuCovarianceFromEuler(const EulerAngles& angles, const Eigen::Matrix3d& euler_covariance) {
  const Eigen::Matrix3d e = eulerToEnuRotation(angles);
  const Eigen::Matrix3d p = e * euler_covariance * e.transpose();
  return 0.5 * (p + p.transpose());
}

Eigen::Quaterniond rotationVectorToQuaternion(const Eigen::Vector3d& v) {
  const double angle = v.norm();
  // sin(angle / 2) / angle, with its limit 1/2 for a tiny angle.
  const double k = 0.5 * sinc(0.5 * angle);
  return Eigen::Quaterniond(std::cos(0.5 * angle), k * v.x(), k * v.y(), k * v.z());
}

}  // namespace core
}  // namespace hrg_gyro
