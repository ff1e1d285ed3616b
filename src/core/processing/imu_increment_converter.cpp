#include "hrg_gyro/core/processing/imu_increment_converter.h"

#include <algorithm>
#include <cmath>

#include "hrg_gyro/core/common/yaml_field.h"

namespace hrg_gyro {
namespace core {

void ImuInputSettings::validate(const std::string& prefix) const {
  if (!imu_to_body.coeffs().allFinite() || std::abs(imu_to_body.norm() - 1.0) > 1e-6) {
    throw ConfigError(prefix + "mounting", "must be a rotation (a unit quaternion, or roll, pitch, yaw in rad)");
  }
  if (!std::isfinite(period) || period < 0.0 || period > 10.0) {
    throw ConfigError(prefix + "period", "must be 0 (the stamps' intervals) or the driver's period in (0, 10] s");
  }
  if (!std::isfinite(max_bridge) || max_bridge < 1.0 || max_bridge > 100.0) {
    throw ConfigError(prefix + "max_bridge", "must be in [1, 100] typical periods");
  }
  if (!std::isfinite(fallback_rate_variance) || fallback_rate_variance < 0.0) {
    throw ConfigError(prefix + "rate_variance", "must be finite and >= 0, (rad/s)^2");
  }
  if (!std::isfinite(max_rate) || !(max_rate > 0.0)) throw ConfigError(prefix + "max_rate", "must be positive, rad/s");
}

ImuIncrementConverter::ImuIncrementConverter(const ImuInputSettings& settings)
    : settings_((settings.validate(), settings)),
      rotation_(settings.imu_to_body.normalized().toRotationMatrix()),
      timeline_(settings.stamp_rule) {}

double ImuIncrementConverter::typicalPeriod() const {
  if (interval_count_ == 0) return 0.0;
  std::array<double, 31> sorted = intervals_;
  const auto end = sorted.begin() + static_cast<std::ptrdiff_t>(interval_count_);
  const auto middle = sorted.begin() + static_cast<std::ptrdiff_t>(interval_count_ / 2);
  std::nth_element(sorted.begin(), middle, end);
  return *middle;
}

std::optional<TriadBodySample> ImuIncrementConverter::convert(const ImuSample& in) {
  if (!in.angular_velocity.allFinite() || in.angular_velocity.norm() > settings_.max_rate) {
    ++counts_.dropped;
    return std::nullopt;
  }
  const StampVerdict verdict = timeline_.check(in.stamp);
  if (!stampUsable(verdict)) {
    ++counts_.dropped;
    return std::nullopt;
  }
  if (last_ == 0 || verdict == StampVerdict::kNewTimeline) {
    last_ = in.stamp;  // no interval yet: the stream starts here
    interval_count_ = interval_next_ = 0;
    ++counts_.timelines;
    return std::nullopt;
  }
  const double interval = toSeconds(in.stamp - last_);
  last_ = in.stamp;
  TriadBodySample out;
  out.stamp = in.stamp;
  const double typical = typicalPeriod();
  const bool gap = verdict == StampVerdict::kResumedAhead ||
                   (typical > 0.0 && interval > settings_.max_bridge * typical) ||
                   (settings_.period > 0.0 && interval > settings_.max_bridge * settings_.period);
  // A gap's interval stays out of the typical period: one hole never teaches the stream its spacing.
  if (!gap) {
    intervals_[interval_next_] = interval;
    interval_next_ = (interval_next_ + 1) % intervals_.size();
    interval_count_ = std::min(interval_count_ + 1, intervals_.size());
  }
  if (gap) {
    out.dt = interval;
    out.flags = kTriadFlagGap;
    ++counts_.gaps;
    return out;
  }
  // The driver's increment: omega times the interval it divided by (its period, or the stamps').
  const double dt = settings_.period > 0.0 && interval <= 1.5 * settings_.period ? settings_.period : interval;
  out.dt = dt;
  out.angular_velocity = rotation_ * in.angular_velocity;
  out.delta_angle = out.angular_velocity * dt;
  const bool given = in.angular_velocity_covariance.allFinite() && in.angular_velocity_covariance(0, 0) != -1.0 &&
                     in.angular_velocity_covariance.diagonal().minCoeff() > 0.0;
  out.covariance = given ? Eigen::Matrix3d(rotation_ * in.angular_velocity_covariance * rotation_.transpose())
                         : Eigen::Matrix3d(settings_.fallback_rate_variance * Eigen::Matrix3d::Identity());
  ++counts_.samples;
  return out;
}

std::optional<Eigen::Vector3d> ImuIncrementConverter::specificForce(const ImuSample& in) const {
  if (!in.has_acceleration || !in.linear_acceleration.allFinite()) return std::nullopt;
  return Eigen::Vector3d(rotation_ * in.linear_acceleration);
}

}  // namespace core
}  // namespace hrg_gyro
