#include "hrg_gyro/core/alignment/attitude_hold.h"

#include <cmath>
#include <stdexcept>

#include "hrg_gyro/core/common/yaml_field.h"
#include "hrg_gyro/core/model/earth_rate.h"

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
  if (!validLatitude(latitude)) throw ConfigError("latitude", kLatitudeRule);
  noise.requireComplete();
  if (std::isnan(scale_factor_sigma)) {
    throw ConfigError("hold/scale_factor_sigma",
                      "not given: the triad's relative scale-factor error, 1 sigma per axis (the triad calibration's K "
                      "standard error; 1e-6 is 1 ppm): a turning body's heading sigma grows with it");
  }
  if (!(scale_factor_sigma >= 0.0) || scale_factor_sigma > 0.1) {
    throw ConfigError("hold/scale_factor_sigma", "must be in [0, 0.1] (relative)");
  }
  if (!std::isfinite(covariance_interval) || !(covariance_interval > 0.0) || covariance_interval > 60.0) {
    throw ConfigError("hold/covariance_interval", "must be in (0, 60] s");
  }
  if (!std::isfinite(max_bridge) || max_bridge < 0.0 || max_bridge > 1.0) {
    throw ConfigError("hold/max_bridge", "must be in [0, 1] s");
  }
}

HoldStart holdStartFrom(const AlignmentResult& aligned) {
  if (!aligned.accepted) throw std::invalid_argument("attitude hold: the alignment was refused: " + aligned.reason);
  if (aligned.single_gyro) throw std::invalid_argument("attitude hold: a single gyro's alignment has no triad to hold");
  HoldStart s;
  s.stamp = aligned.last_sample > 0 ? aligned.last_sample : aligned.end;
  s.body_to_enu = aligned.body_orientation;
  s.covariance_enu = aligned.covariance_enu;
  s.bias_variance = aligned.bias_variance;
  s.attitude_bias_covariance = aligned.attitude_bias_covariance;
  double sum = 0.0;
  for (double w : aligned.white_noise) sum += w * w;
  s.white_noise = aligned.white_noise.empty() ? 0.0 : std::sqrt(sum / static_cast<double>(aligned.white_noise.size()));
  return s;
}

namespace {

StampRule holdStampRule() {
  StampRule rule;
  rule.backward_reset = 0.5;
  rule.forward_jump = 1.0;
  rule.persist = 5;
  return rule;
}

}  // namespace

AttitudeHold::AttitudeHold(const AttitudeHoldSettings& settings, const HoldStart& start)
    : settings_(settings),
      earth_(earthRateEnu(settings.latitude)),
      q_(start.body_to_enu.normalized()),
      timeline_(holdStampRule()) {
  settings_.validate();
  if (!start.covariance_enu.allFinite() || !start.attitude_bias_covariance.allFinite() ||
      !std::isfinite(start.bias_variance) || start.bias_variance < 0.0 || !start.body_to_enu.coeffs().allFinite()) {
    throw std::invalid_argument("attitude hold: the start's orientation and covariances must be finite");
  }
  p_.setZero();
  p_.topLeftCorner<3, 3>() = start.covariance_enu;
  p_.block<3, 3>(3, 3) = start.bias_variance * Eigen::Matrix3d::Identity();
  p_.block<3, 3>(0, 3) = start.attitude_bias_covariance;
  p_.block<3, 3>(3, 0) = start.attitude_bias_covariance.transpose();
  p_.bottomRightCorner<3, 3>() =
      settings_.scale_factor_sigma * settings_.scale_factor_sigma * Eigen::Matrix3d::Identity();
  white_noise_ = settings_.noise.angle_white_noise > 0.0 ? settings_.noise.angle_white_noise : start.white_noise;
  white_variance_ = 2.0 * white_noise_ * white_noise_;
  stamp_ = start.stamp;
  if (stamp_ > 0) timeline_.check(stamp_);
  last_rate_ = q_.conjugate() * earth_;  // a body at rest
}

void AttitudeHold::lose(const std::string& reason) {
  if (lost_.empty()) lost_ = reason;
}

void AttitudeHold::propagate(State* p) const {
  if (block_ <= 0.0) return;
  State phi = State::Identity();
  phi.topLeftCorner<3, 3>() -= skew(earth_) * block_;
  phi.block<3, 3>(0, 3) = -block_c_dt_;
  phi.block<3, 3>(0, 6) = -block_c_angle_;
  const GyroNoiseModel& n = settings_.noise;
  State q = State::Zero();
  q.topLeftCorner<3, 3>().diagonal().setConstant(n.angle_random_walk * n.angle_random_walk * block_);
  q.block<3, 3>(3, 3).diagonal().setConstant(n.rate_random_walk * n.rate_random_walk * block_);
  // The walk of the bias within the block reaches the attitude too (second order in the block).
  const double k2 = n.rate_random_walk * n.rate_random_walk;
  q.topLeftCorner<3, 3>().diagonal().array() += k2 * block_ * block_ * block_ / 3.0;
  q.block<3, 3>(0, 3) = -k2 * 0.5 * block_ * block_c_dt_;
  q.block<3, 3>(3, 0) = q.block<3, 3>(0, 3).transpose();
  q.topLeftCorner<3, 3>() += bridge_;
  *p = phi * (*p) * phi.transpose() + q;
  *p = 0.5 * (*p + p->transpose());
}

bool AttitudeHold::timed(const TriadBodySample& sample) {
  if (!std::isfinite(sample.dt) || !(sample.dt > 0.0) || !sample.delta_angle.allFinite() || sample.stamp <= stamp_) {
    ++dropped_;
    return false;
  }
  const StampVerdict v = timeline_.check(sample.stamp);
  if (v == StampVerdict::kNewTimeline || v == StampVerdict::kResumedAhead) {
    lose(std::string("the triad's stamps ") + (v == StampVerdict::kNewTimeline ? "went back" : "jumped ahead") +
         " for good: the body's turn in between is unknown; align again");
    return false;
  }
  const double spacing = toSeconds(sample.stamp - stamp_);
  // A glitched stamp, or a dt its stamps contradict: the sample is dropped, the next one bridges it.
  if (!stampUsable(v) || sample.dt > 1.5 * spacing) {
    ++dropped_;
    return false;
  }
  const double missing = spacing - sample.dt;
  if (missing <= 0.5 * sample.dt) return true;
  if (missing > settings_.max_bridge) {
    lose("triad samples missing for " + std::to_string(missing) + " s before the one at " +
         std::to_string(toSeconds(sample.stamp)) + " s (hold/max_bridge " + std::to_string(settings_.max_bridge) +
         " s): the body's turn over them is unknown; align again");
    return false;
  }
  // Bridged at the last rate; that rate's own noise (two angle noises over one sample) over the gap.
  const double rate_sigma = std::sqrt(2.0) * white_noise_ / sample.dt;
  bridge_ += (rate_sigma * missing) * (rate_sigma * missing) * Eigen::Matrix3d::Identity();
  integrate(last_rate_ * missing, missing);
  bridged_ += static_cast<std::uint64_t>(std::llround(missing / sample.dt));
  return true;
}

void AttitudeHold::integrate(const Eigen::Vector3d& increment, double dt) {
  const Eigen::Matrix3d c = q_.toRotationMatrix();
  block_c_dt_ += c * dt;
  block_c_angle_ += c * increment.asDiagonal();
  block_ += dt;
  q_ = rotationVectorToQuaternion(-earth_ * dt) * q_ * rotationVectorToQuaternion(increment);
  if ((++samples_ & 1023u) == 0) q_.normalize();
  elapsed_ += dt;
  if (block_ >= settings_.covariance_interval) {
    propagate(&p_);
    block_ = 0.0;
    block_c_dt_.setZero();
    block_c_angle_.setZero();
    bridge_.setZero();
  }
}

bool AttitudeHold::add(const TriadBodySample& sample) {
  if (!lost_.empty()) return false;
  if (!sample.integrated()) {
    lose("a gap or reset in the triad's samples: the body's turn over it is unknown; align again");
    return false;
  }
  if (sample.flags & kTriadFlagPrecessing) {
    lose("a wave was turned on command (FLAG_PRECESSING): the triad's rate is not the body's; align again");
    return false;
  }
  if (!timed(sample)) return lost_.empty();
  integrate(sample.delta_angle, sample.dt);
  last_rate_ = sample.delta_angle / sample.dt;
  stamp_ = sample.stamp;
  return true;
}

Eigen::Matrix<double, 9, 9> AttitudeHold::stateCovariance() const {
  State p = p_;
  propagate(&p);
  return p;
}

Eigen::Matrix3d AttitudeHold::covariance() const {
  return stateCovariance().topLeftCorner<3, 3>() + white_variance_ * Eigen::Matrix3d::Identity();
}

double AttitudeHold::headingSigma() const { return std::sqrt(std::max(covarianceRpy()(2, 2), 0.0)) * 180.0 / kPi; }

}  // namespace core
}  // namespace hrg_gyro
