// Any IMU's rate stream as the gyrocompass's input: each sensor_msgs/Imu-like sample (a stamp, the
// angular velocity and optionally the specific force, in the IMU's own frame) turned back into the
// body-frame increment a triad sample carries,
//
//   delta_angle_body = R (omega dt)        R: the IMU's frame -> the body (its mounting)
//
// with dt the time since the previous sample, or the driver's nominal period when it divided each
// delta-angle by that (`period`): either way the increment a driver that differenced delta-angles
// started from. The stamps follow the one stamp rule (common/stamp_timeline.h): a zero, duplicate,
// out-of-order or jumped stamp is dropped and counted, and the stream goes on where it was. The first
// sample (and the first after a new timeline) has no interval: it starts the stream and yields none.
// An interval up to `max_bridge` typical periods (the median of the last 31) is integrated as it is:
// a lost sample costs its own increment only (at rest the next sample's rate stands for it). A longer
// one is a gap (kTriadFlagGap, no increment), never a rotation, so an hour's hole in the stamps
// never turns the attitude. The rate's covariance is the message's (rotated) when it gave one, else
// `fallback_rate_variance` on each axis. Nothing non-finite is emitted. No ROS.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <optional>
#include <string>

#include "hrg_gyro/core/common/stamp_timeline.h"
#include "hrg_gyro/core/common/units.h"
#include "hrg_gyro/core/processing/triad_combiner.h"

namespace hrg_gyro {
namespace core {

struct ImuInputSettings {
  /// The IMU's frame -> the body frame the gyrocompass reports (REP-103 FLU), a rotation.
  Eigen::Quaterniond imu_to_body = Eigen::Quaterniond::Identity();
  /// s; 0: each increment over the time since the previous stamp. > 0: the driver's nominal sample
  /// period, by which it divided each delta-angle (the increment is then omega times it).
  double period = 0.0;
  /// Typical periods an interval may span and still be integrated (one lost sample: 2).
  double max_bridge = 2.5;
  /// (rad/s)^2 on each axis when a sample brings no covariance (REP-145: all 0, or [0] = -1).
  double fallback_rate_variance = 0.0;
  /// rad/s; a sample above it is no measurement of a base at rest or swaying: dropped.
  double max_rate = 20.0;
  StampRule stamp_rule{0.5, 1.0, 5};
  /// Throws ConfigError naming the field for a rotation that is not one, or a bad number.
  void validate(const std::string& prefix = "imu/") const;
};

/// One IMU sample as the converter reads it (a sensor_msgs/Imu's fields).
struct ImuSample {
  Nanoseconds stamp = 0;
  Eigen::Vector3d angular_velocity = Eigen::Vector3d::Zero();  ///< rad/s, the IMU's frame
  /// (rad/s)^2, the IMU's frame; all 0 or (0,0) = -1: not given (REP-145).
  Eigen::Matrix3d angular_velocity_covariance = Eigen::Matrix3d::Zero();
  Eigen::Vector3d linear_acceleration = Eigen::Vector3d::Zero();  ///< m/s^2, the IMU's frame
  bool has_acceleration = false;                                  ///< linear_acceleration_covariance[0] != -1
};

struct ImuInputCounts {
  std::uint64_t samples = 0;    ///< integrated samples emitted
  std::uint64_t gaps = 0;       ///< intervals too long to integrate: gap samples emitted
  std::uint64_t dropped = 0;    ///< stamps the rule dropped, non-finite or implausible rates
  std::uint64_t timelines = 0;  ///< the stream started (1) or restarted on a new timeline
};

class ImuIncrementConverter {
 public:
  /// Throws ConfigError (settings.validate()).
  explicit ImuIncrementConverter(const ImuInputSettings& settings);

  /// The body sample of `in`'s interval, or none (the first of a stream, or dropped).
  std::optional<TriadBodySample> convert(const ImuSample& in);
  /// The specific force in the body frame (m/s^2), for the level; none without one or non-finite.
  std::optional<Eigen::Vector3d> specificForce(const ImuSample& in) const;

  const ImuInputCounts& counts() const { return counts_; }
  /// s, the median of the last intervals (0 before two samples).
  double typicalPeriod() const;
  const ImuInputSettings& settings() const { return settings_; }

 private:
  ImuInputSettings settings_;
  Eigen::Matrix3d rotation_;
  StampTimeline timeline_;
  Nanoseconds last_ = 0;  // the previous usable stamp (0: none)
  std::array<double, 31> intervals_{};
  std::size_t interval_count_ = 0, interval_next_ = 0;
  ImuInputCounts counts_;
};

}  // namespace core
}  // namespace hrg_gyro
