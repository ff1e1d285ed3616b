// The outcome of an alignment: the attitude found (orientation body -> ENU, roll, pitch, yaw, the
// navigator's true heading), its covariance, the heading's error budget, what each segment of the
// window left (the residuals per indexer position, per commanded rate), and, when refused, the gate
// and the reason. The gyrocompass node publishes it, `hrg_bag align` prints it and writes it as YAML
// (emitAlignmentResult); both read the same object. Frames and signs: local_level.h. No ROS.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <string>
#include <vector>

#include "hrg_gyro/core/alignment/alignment_settings.h"
#include "hrg_gyro/core/alignment/earth_checks.h"
#include "hrg_gyro/core/alignment/earth_rate_heading.h"
#include "hrg_gyro/core/common/units.h"

namespace hrg_gyro {
namespace core {

/// One segment of the window: an indexer position, a commanded rate of the sweep, a stretch between gaps.
struct AlignmentSegment {
  int channel = -1;               ///< -1: every channel below; the sweep: the axis (0, 1, 2)
  double start = 0.0, end = 0.0;  ///< s from the window's start
  double indexer_angle = NAN;     ///< rad, mean indexer angle (indexed), NaN otherwise
  double commanded_rate = NAN;    ///< rad/s, electrical (sweep), NaN otherwise
  /// Per channel (body axes x, y, z; one for a single gyro): the slope of the fit's residuals, its
  /// standard error (rad/s), and the rms residual angle against the noise model's (rad).
  std::vector<double> residual_rate, residual_rate_std, rms, predicted_rms;
};

/// A step of the base (a lean, a knock) the still-base fit carried: where the window was cut and the
/// rotation the gyros measured across it.
struct BaseStepRecord {
  double time = 0.0;                                   ///< s from the window's start
  Eigen::Vector3d rotation = Eigen::Vector3d::Zero();  ///< rad, body axes (static) or channels (indexed)
  double chi_square = 0.0;                             ///< of the step against none
};

struct AlignmentResult {
  bool accepted = false;
  /// The check that refused it: "input", "noise", "latitude", "motion", "level", "design", "sweep",
  /// "stillness", "earth_rate", "earth_check", "attitude", "aborted"; empty when accepted.
  std::string gate;
  std::string reason;  ///< why it was refused, or the one-line summary
  std::vector<std::string> notes;

  AlignmentMode mode = AlignmentMode::kStatic;
  bool single_gyro = false;
  /// The frame whose attitude is given: "body" (static, sweep) or "indexer" (the indexer's zero frame).
  std::string frame = "body";
  Nanoseconds start = 0, end = 0;  ///< the window, gyro stamps
  Nanoseconds last_sample = 0;     ///< the stamp of the window's last gyro sample: where the attitude is given
  double seconds = 0.0;            ///< s of data used
  std::uint64_t samples = 0;       ///< gyro samples used (per channel)

  EulerAngles attitude;                                             ///< rad, of `frame`
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();  ///< `frame` -> ENU
  Eigen::Matrix3d covariance_rpy = Eigen::Matrix3d::Zero();         ///< rad^2, (roll, pitch, yaw)
  Eigen::Matrix3d covariance_enu = Eigen::Matrix3d::Zero();         ///< rad^2, ENU small rotation
  double heading = NAN;        ///< deg, true heading of the frame's x axis, clockwise from North
  double heading_sigma = NAN;  ///< deg, 1 sigma

  /// The triad's body at the window's end (indexed: turned by the indexer), -> ENU: where an
  /// attitude hold starts; its ENU covariance is covariance_enu.
  Eigen::Quaterniond body_orientation = Eigen::Quaterniond::Identity();
  /// For an attitude hold: the variance per body axis of the constant bias the triad carries at rest
  /// ((rad/s)^2: the calibration's residual bias and its D(theta) at resting waves), and the
  /// covariance of the attitude error (ENU) with that bias (rad rad/s): a static alignment's heading
  /// error and the bias that caused it are one, and cancel in the hold's drift.
  double bias_variance = 0.0;
  Eigen::Matrix3d attitude_bias_covariance = Eigen::Matrix3d::Zero();

  Eigen::Vector3d levelled_rate = Eigen::Vector3d::Zero();  ///< rad/s, the Earth's rate measured, levelled
  double horizontal_rate = 0.0, horizontal_rate_std = 0.0;  ///< rad/s: against Omega cos(lat)
  HeadingErrorBudget budget;
  std::vector<double> white_noise;     ///< rad per sample, per channel (measured or given)
  double scatter = 0.0;                ///< worst channel's rms residual over the noise model's
  double worst_motion = 0.0;           ///< rad/s, largest block departure
  double accelerometer_gravity = NAN;  ///< m/s^2, |mean specific force| (accelerometer level)
  std::vector<AlignmentSegment> segments;

  /// Which estimator answered, "still_base" (the Earth's rate fitted on the integrated angles, the
  /// base's steps carried) or "tracking" (the gyros track the body, gravity followed in the inertial
  /// frame), and why.
  std::string estimator = "still_base";
  std::string estimator_reason;
  std::vector<BaseStepRecord> base_steps;  ///< the steps the still-base fit carried
  double excluded_seconds = 0.0;           ///< s of the window left out around them
  double low_frequency_scatter = 0.0;      ///< rms of block-mean residuals over the noise model's
  double low_frequency_limit = INFINITY;   ///< what a still base exceeds once in 1 / motion/block_false_alarm
  std::vector<EarthCheck> earth_checks;    ///< of the estimator that answered
  /// The tracking estimator's heading and sigma (deg) when it ran, and the two estimators' heading
  /// difference over its standard error (their noise), NaN when only one ran.
  double tracking_heading = NAN, tracking_heading_sigma = NAN, estimator_difference = NAN;
  double velocity_white = NAN, velocity_random_walk = NAN;  ///< m/s, m/s/sqrt(s): the tracking's measured noise
  std::string noise_sources;                                ///< where each noise term came from

  /// One line: heading +- sigma, mode, window, the budget's main terms; or the refusal.
  std::string summary() const;
};

/// The result as a YAML document (every number with its unit in the key's comment), for
/// `hrg_bag align` and the report.
std::string emitAlignmentResult(const AlignmentResult& result);

}  // namespace core
}  // namespace hrg_gyro
