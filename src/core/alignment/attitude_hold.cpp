#include "hrg_gyro/core/alignment/attitude_hold.h"

#include <cmath>
#include <stdexcept>

#include "hrg_gyro/core/common/yaml_field.h"

namespace hrg_gyro {
namespace core {
namespace {

Eigen::Matrix3d skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
  return m;
}

}  // namespace

void AttitudeHoldSettings::validate() const {
  if (!std::isfinite(latitude) || std::abs(latitude) > 0.5 * kPi) {
    throw ConfigError("latitude", "must be given, in [-pi/2, pi/2] rad");
  }
  noise.validate();
  if (!std::isfinite(covariance_interval) || !(covariance_interval > 0.0) || covariance_interval > 60.0) {
    throw ConfigError("hold/covariance_interval", "must be in (0, 60] s");
  }
}

HoldStart holdStartFrom(const AlignmentResult& aligned) {
  if (!aligned.accepted) throw std::invalid_argument("attitude hold: the alignment was refused: " + aligned.reason);
  if (aligned.single_gyro) throw std::invalid_argument("attitude hold: a single gyro's alignment has no triad to hold");
  HoldStart s;
  s.stamp = aligned.end;
  s.body_to_enu = aligned.body_orientation;
  s.covariance_enu = aligned.covariance_enu;
  s.bias_variance = aligned.bias_variance;
  s.attitude_bias_covariance = aligned.attitude_bias_covariance;
  double sum = 0.0;
  for (double w : aligned.white_noise) sum += w * w;
  s.white_noise = aligned.white_noise.empty() ? 0.0 : std::sqrt(sum / static_cast<double>(aligned.white_noise.size()));
  return s;
}

AttitudeHold::AttitudeHold(const AttitudeHoldSettings& settings, const HoldStart& start)
    : settings_(settings), earth_(earthRateEnu(settings.latitude)), q_(start.body_to_enu.normalized()) {
  settings_.validate();
  if (!start.covariance_enu.allFinite() || !start.attitude_bias_covariance.allFinite() ||
      !std::isfinite(start.bias_variance) || start.bias_variance < 0.0 || !start.body_to_enu.coeffs().allFinite()) {
    throw std::invalid_argument("attitude hold: the start's orientation and covariances must be finite");
  }
  p_.setZero();
  p_.topLeftCorner<3, 3>() = start.covariance_enu;
  p_.bottomRightCorner<3, 3>() = start.bias_variance * Eigen::Matrix3d::Identity();
  p_.topRightCorner<3, 3>() = start.attitude_bias_covariance;
  p_.bottomLeftCorner<3, 3>() = start.attitude_bias_covariance.transpose();
  const double s = settings_.noise.angle_white_noise > 0.0 ? settings_.noise.angle_white_noise : start.white_noise;
  white_variance_ = 2.0 * s * s;
  stamp_ = start.stamp;
}

void AttitudeHold::lose(const std::string& reason) {
  if (lost_.empty()) lost_ = reason;
}

void AttitudeHold::propagate(Eigen::Matrix<double, 6, 6>* p) const {
  if (block_ <= 0.0) return;
  Eigen::Matrix<double, 6, 6> phi = Eigen::Matrix<double, 6, 6>::Identity();
  phi.topLeftCorner<3, 3>() -= skew(earth_) * block_;
  phi.topRightCorner<3, 3>() = -block_c_dt_;
  const GyroNoiseModel& n = settings_.noise;
  Eigen::Matrix<double, 6, 6> q = Eigen::Matrix<double, 6, 6>::Zero();
  q.topLeftCorner<3, 3>().diagonal().setConstant(n.angle_random_walk * n.angle_random_walk * block_);
  q.bottomRightCorner<3, 3>().diagonal().setConstant(n.rate_random_walk * n.rate_random_walk * block_);
  // The walk of the bias within the block reaches the attitude too (second order in the block).
  const double k2 = n.rate_random_walk * n.rate_random_walk;
  q.topLeftCorner<3, 3>().diagonal().array() += k2 * block_ * block_ * block_ / 3.0;
  q.topRightCorner<3, 3>() = -k2 * 0.5 * block_ * block_c_dt_;
  q.bottomLeftCorner<3, 3>() = q.topRightCorner<3, 3>().transpose();
  *p = phi * (*p) * phi.transpose() + q;
  *p = 0.5 * (*p + p->transpose());
}

bool AttitudeHold::add(const TriadBodySample& sample) {
  if (!lost_.empty()) return false;
  if (sample.stamp <= stamp_ || !std::isfinite(sample.dt) || !(sample.dt > 0.0) || !sample.delta_angle.allFinite()) {
    ++dropped_;
    return true;
  }
  if (!sample.integrated()) {
    lose("a gap or reset in the triad's samples: the body's turn over it is unknown; align again");
    return false;
  }
  if (sample.flags & kTriadFlagPrecessing) {
    lose("a wave was turned on command (FLAG_PRECESSING): the triad's rate is not the body's; align again");
    return false;
  }
  const double missing = toSeconds(sample.stamp - stamp_) - sample.dt;
  if (missing > 0.5 * sample.dt) {
    lose("triad samples missing before the one at " + std::to_string(toSeconds(sample.stamp)) +
         " s: the body's turn over them is unknown; align again");
    return false;
  }
  const double dt = sample.dt;
  block_c_dt_ += q_.toRotationMatrix() * dt;
  block_ += dt;
  q_ = rotationVectorToQuaternion(-earth_ * dt) * q_ * rotationVectorToQuaternion(sample.delta_angle);
  if ((++samples_ & 1023u) == 0) q_.normalize();
  stamp_ = sample.stamp;
  elapsed_ += dt;
  if (block_ >= settings_.covariance_interval) {
    propagate(&p_);
    block_ = 0.0;
    block_c_dt_.setZero();
  }
  return true;
}

Eigen::Matrix<double, 6, 6> AttitudeHold::stateCovariance() const {
  Eigen::Matrix<double, 6, 6> p = p_;
  propagate(&p);
  return p;
}

Eigen::Matrix3d AttitudeHold::covariance() const {
  return stateCovariance().topLeftCorner<3, 3>() + white_variance_ * Eigen::Matrix3d::Identity();
}

double AttitudeHold::headingSigma() const { return std::sqrt(std::max(covarianceRpy()(2, 2), 0.0)) * 180.0 / kPi; }

}  // namespace core
}  // namespace hrg_gyro
