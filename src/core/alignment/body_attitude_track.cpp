#include "hrg_gyro/core/alignment/body_attitude_track.h"

#include <algorithm>
#include <cmath>

#include "hrg_gyro/core/alignment/local_level.h"

namespace hrg_gyro {
namespace core {

BodyAttitudeTrack::BodyAttitudeTrack(double start) {
  time_.push_back(start);
  attitude_.push_back(Eigen::Quaterniond::Identity());
  increment_.push_back(Eigen::Vector3d::Zero());
  integral_.push_back(Eigen::Matrix3d::Zero());
}

bool BodyAttitudeTrack::add(double t, double dt, const Eigen::Vector3d& increment) {
  if (!(dt > 0.0) || !std::isfinite(t) || !increment.allFinite() || std::abs(t - dt - time_.back()) > 0.1 * dt) {
    return false;
  }
  const Eigen::Vector3d corrected = increment + previous_.cross(increment) / 12.0;
  previous_ = increment;
  const Eigen::Quaterniond half = attitude_.back() * rotationVectorToQuaternion(0.5 * corrected);
  const double length = t - time_.back();
  integral_.push_back(integral_.back() + half.toRotationMatrix() * length);  // midpoint rule
  Eigen::Quaterniond next = attitude_.back() * rotationVectorToQuaternion(corrected);
  if ((attitude_.size() & 1023u) == 0) next.normalize();
  attitude_.push_back(next);
  increment_.push_back(corrected);
  time_.push_back(t);
  return true;
}

std::size_t BodyAttitudeTrack::segmentOf(double t) const {
  const auto it = std::lower_bound(time_.begin() + 1, time_.end(), t);
  return it == time_.end() ? time_.size() - 1 : static_cast<std::size_t>(it - time_.begin());
}

Eigen::Matrix3d BodyAttitudeTrack::attitudeAt(double t) const {
  if (time_.size() < 2 || t <= time_.front()) return attitude_.front().toRotationMatrix();
  if (t >= time_.back()) return attitude_.back().toRotationMatrix();
  const std::size_t k = segmentOf(t);
  const double f = (t - time_[k - 1]) / (time_[k] - time_[k - 1]);
  return (attitude_[k - 1] * rotationVectorToQuaternion(f * increment_[k])).toRotationMatrix();
}

Eigen::Matrix3d BodyAttitudeTrack::biasResponseAt(double t) const {
  if (time_.size() < 2 || t <= time_.front()) return Eigen::Matrix3d::Zero();
  if (t >= time_.back()) return integral_.back();
  const std::size_t k = segmentOf(t);
  const double f = (t - time_[k - 1]) / (time_[k] - time_[k - 1]);
  return integral_[k - 1] + f * (integral_[k] - integral_[k - 1]);
}

Eigen::Vector3d BodyAttitudeTrack::meanRate() const {
  const double length = end() - start();
  if (!(length > 0.0)) return Eigen::Vector3d::Zero();
  const Eigen::AngleAxisd a(attitude_.back().normalized());
  return a.axis() * a.angle() / length;
}

}  // namespace core
}  // namespace hrg_gyro
