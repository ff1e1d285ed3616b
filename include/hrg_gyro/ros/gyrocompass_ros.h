// ROS wrapper of the gyrocompass (node gyrocompass, nodelet hrg_gyro/Gyrocompass): the body's true
// heading, roll and pitch from the Earth's rotation (north-finding), then the attitude held on the
// triad's increments.
//
// Its settings are core::AlignmentSettings, read from the private parameters by the core's parser (a
// bad or unknown key stops the node, naming it). `~align` (StartAlignment) starts one alignment of a
// window of gyro stamps, fed to one core::Gyrocompass (the object `hrg_bag align` feeds: same records,
// same result); `~align_at_startup` starts one at once. Inputs (relative topics), by mode: the triad's
// `triad/output` (static, indexed), one gyro's `output` (indexed, single_gyro), `<axis>/output` and
// `<axis>/precession/state` per axis of ~triad_file (sweep), the indexer's `turntable/state`
// (indexed), an accelerometer's `accel/data_raw` (level/source accelerometer). Outputs, latched:
// `alignment/result` (AlignmentResult) and, when accepted, `alignment/imu` (sensor_msgs/Imu: the
// body's orientation -> ENU with its covariance, angular velocity and acceleration marked not
// measured), so a navigation filter fuses it as an absolute attitude. After an accepted alignment of
// the triad, a core::AttitudeHold integrates `triad/output` from the aligned attitude and `imu/data`
// carries the held orientation with its growing covariance and the triad's angular velocity. With
// `gyro_input: imu` the gyros are any IMU's `imu/data_raw` (sensor_msgs/Imu) instead of the triad:
// each message turned back into a body increment (core::ImuIncrementConverter, its mounting from
// `imu/mounting`), its linear_acceleration the level's accelerometer, the hold on its behalf. The
// vehicle's own travel over the Earth is out of scope: the hold is for a base at or near its site.
// Diagnostics: `gyrocompass` (progress, the last result and its budget) and `attitude hold`; either
// turns ERROR "input stalled" when its gyro stream has been quiet for `~stall_timeout` s of wall time
// (a stalled alignment is replaced by the next `~align`).
#pragma once

#include <diagnostic_updater/diagnostic_updater.h>
#include <ros/ros.h>
#include <sensor_msgs/Imu.h>

#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "hrg_gyro/GyroOutput.h"
#include "hrg_gyro/PrecessionState.h"
#include "hrg_gyro/StartAlignment.h"
#include "hrg_gyro/TriadOutput.h"
#include "hrg_gyro/TurntableState.h"
#include "hrg_gyro/core/alignment/attitude_hold.h"
#include "hrg_gyro/core/alignment/gyrocompass.h"
#include "hrg_gyro/ros/parameter_reader.h"

namespace hrg_gyro {

class GyrocompassRos {
 public:
  /// Throws std::exception for a bad or unknown parameter at start-up, naming it.
  GyrocompassRos(ros::NodeHandle nh, ros::NodeHandle pnh);
  ~GyrocompassRos();

  /// The private parameters as read at start-up (unknown and defaulted keys).
  const ParameterReader& parameters() const { return params_; }

 private:
  /// The topics the configured mode and gyro input need (the gyro stream also for the hold).
  void subscribe(int queue_size);
  void onTriad(const TriadOutput::ConstPtr& msg);
  void onImu(const sensor_msgs::Imu::ConstPtr& msg);
  /// One body sample of the gyro stream (the triad's, or the IMU's converted) to the hold and to the
  /// running alignment; `frame`: the frame the results are reported in.
  void takeBodySample(const core::TriadBodySample& sample, const std::string& frame);
  void onGyro(const GyroOutput::ConstPtr& msg);
  void onSweepAxis(std::size_t axis, const GyroOutput::ConstPtr& msg);
  void onPrecession(std::size_t axis, const PrecessionState::ConstPtr& msg);
  void onIndexer(const TurntableState::ConstPtr& msg);
  void onAccelerometer(const sensor_msgs::Imu::ConstPtr& msg);
  bool onAlign(StartAlignment::Request& req, StartAlignment::Response& res);

  /// Starts an alignment (under the lock): "" when it runs, else why not.
  std::string start(double duration, const std::string& mode);
  /// Ends the running alignment when its window is full (or it was refused): publishes the result,
  /// starts the hold when accepted.
  void finishIfComplete();
  /// The running alignment took a sample (or filled) since `samples_before`: its input moves.
  void noteProgress(std::uint64_t samples_before);
  /// Seconds of wall time since `since`.
  static double quietFor(const ros::WallTime& since) { return (ros::WallTime::now() - since).toSec(); }
  bool alignmentStalled() const { return running_ && quietFor(alignment_input_) > stall_timeout_; }
  void diagnoseAlignment(diagnostic_updater::DiagnosticStatusWrapper& stat);
  void diagnoseHold(diagnostic_updater::DiagnosticStatusWrapper& stat);

  ros::NodeHandle nh_, pnh_;
  ParameterReader params_;
  std::mutex mutex_;  // everything below (nodelets may run callbacks concurrently)
  core::AlignmentSettings settings_;
  core::TriadParameters triad_;  // ~triad_file's (sweep); default when none
  bool have_triad_file_ = false;
  bool hold_enabled_ = true;
  std::unique_ptr<core::ImuIncrementConverter> imu_;  // gyro_input imu
  bool imu_accelerometer_ = false;                    // the level's specific force from imu/data_raw
  std::string gyro_topic_;                            // triad/output or imu/data_raw, resolved
  core::AttitudeHoldSettings hold_settings_;
  std::unique_ptr<core::Gyrocompass> running_;
  std::string running_frame_;      // the frame_id of the gyro messages fed to it
  std::string running_topic_;      // the gyro stream it reads (for the stall diagnostic)
  double stall_timeout_ = 1.0;     // s of wall time
  ros::WallTime alignment_input_;  // the running alignment's last gyro message (or its start)
  ros::WallTime hold_input_;       // the hold's last triad message (or its start)
  std::optional<core::AlignmentResult> last_;
  std::unique_ptr<core::AttitudeHold> hold_;
  std::string hold_frame_;
  std::uint64_t alignments_ = 0;

  std::vector<ros::Subscriber> subscribers_;
  ros::Publisher result_pub_, alignment_imu_pub_, imu_pub_;
  ros::ServiceServer align_srv_;
  diagnostic_updater::Updater updater_;
  ros::WallTimer diagnostics_timer_;
};

}  // namespace hrg_gyro
