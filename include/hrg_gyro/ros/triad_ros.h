// ROS wrapper of the triad (node triad, nodelet hrg_gyro/Triad): three gyros' processors in, one
// body-frame IMU out.
//
// For each axis named in ~triad_file it subscribes `<axis>/output` (GyroOutput) and, for the axis's
// rate variance, `<axis>/imu/data_raw` (the processor's Imu, angular_velocity_covariance[8]); the
// two are paired by stamp (core::TriadVariancePairing) and combined across axes by stamp
// (core::TriadCombiner, the object `hrg_bag process --triad` runs, hence identical numbers). It
// publishes `triad/output` (TriadOutput, every triad sample, flagged ones included) and
// `imu/data_raw` (sensor_msgs/Imu, REP-145, in the file's frame_id; none for a sample flagged
// GAP or RESET). `~reload` (std_srvs/Trigger) re-reads the triad file and swaps M and the bias
// between two samples; a bad file is refused with the offending key and the previous one stays.
// Health per axis and of the triad goes to /diagnostics. Subscriptions take ConstPtr: in one
// nodelet manager with the processors nothing is copied or serialised.
#pragma once

#include <diagnostic_updater/diagnostic_updater.h>
#include <diagnostic_updater/update_functions.h>
#include <ros/ros.h>
#include <sensor_msgs/Imu.h>
#include <std_srvs/Trigger.h>

#include <array>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "hrg_gyro/GyroOutput.h"
#include "hrg_gyro/core/processing/triad_combiner.h"
#include "hrg_gyro/core/processing/triad_variance_pairing.h"
#include "hrg_gyro/ros/input_thread.h"
#include "hrg_gyro/ros/parameter_reader.h"
#include "hrg_gyro/ros/reload_record.h"

namespace hrg_gyro {

class TriadRos {
 public:
  /// Throws std::exception when ~triad_file is missing or invalid, or a setting is, at start-up.
  TriadRos(ros::NodeHandle nh, ros::NodeHandle pnh);
  ~TriadRos();

  /// The private parameters as read at start-up (unknown and defaulted keys).
  const ParameterReader& parameters() const { return params_; }

 private:
  /// What the diagnostics know of one axis between two reports.
  struct AxisHealth {
    ros::WallTime last_wall;
    bool seen = false;
    std::uint64_t outputs = 0, reported_outputs = 0;
    ros::WallTime reported_wall;
    core::TriadAxisCounters reported;
    std::uint64_t reported_without_variance = 0;
    std::uint8_t last_flags = 0;
  };

  void onOutput(std::size_t axis, const GyroOutput::ConstPtr& msg);
  void onImu(std::size_t axis, const sensor_msgs::Imu::ConstPtr& msg);
  /// Combines the axis outputs now ready and publishes the triad samples they complete.
  void combineReady(std::size_t axis);
  bool onReload(std_srvs::Trigger::Request& req, std_srvs::Trigger::Response& res);
  void diagnoseAxis(std::size_t axis, diagnostic_updater::DiagnosticStatusWrapper& stat);
  void diagnoseTriad(diagnostic_updater::DiagnosticStatusWrapper& stat);
  /// Why the axes' outputs since the last triad report gave no (or not only) combined samples: each
  /// axis that sent nothing, waits for its variance, lacks stamps, or has mismatched, flagged or
  /// dropped outputs, by name. "" when no axis shows a cause.
  std::string whyNotCombined(const std::array<std::uint64_t, 3>& arrived) const;
  void diagnoseFile(diagnostic_updater::DiagnosticStatusWrapper& stat);

  ros::NodeHandle nh_, pnh_;
  ParameterReader params_;
  std::mutex mutex_;  // the combiner, the pairings and the health (nodelets may run callbacks concurrently)
  std::string triad_file_;
  std::unique_ptr<core::TriadCombiner> combiner_;
  std::array<core::TriadVariancePairing, 3> pairings_;
  double fixed_variance_ = -1.0;  // (rad/s)^2; negative: each axis's from its imu/data_raw
  double stall_timeout_ = 0.5;
  std::vector<core::AxisOutput> ready_;           // reused: outputs paired with their variance
  std::vector<core::TriadBodySample> completed_;  // reused: triad samples to publish

  InputThread input_;  // serves the six axis subscriptions, in arrival order
  std::vector<ros::Subscriber> subscribers_;
  ros::Publisher imu_pub_, output_pub_;
  ros::ServiceServer reload_srv_;

  diagnostic_updater::Updater updater_;
  ros::WallTimer diagnostics_timer_;
  double expected_rate_ = 200.0;
  double min_rate_ = 0.0, max_rate_ = 0.0;
  std::unique_ptr<diagnostic_updater::FrequencyStatus> frequency_;
  std::array<AxisHealth, 3> health_;
  core::TriadCounters reported_;                     // the combiner's counters at the last triad report
  std::array<std::uint64_t, 3> reported_outputs_{};  // each axis's outputs received then
  ros::WallTime reported_wall_;                      // and when
  ReloadRecord reload_{"triad", "triad"};
  ros::Time last_stamp_;
};

}  // namespace hrg_gyro
