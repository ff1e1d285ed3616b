// ROS wrapper of the measurement pipeline (node processor, nodelet hrg_gyro/Processor).
//
// Subscribes `channels`, runs core::GyroProcessor (the same object `hrg_bag process` runs, hence
// identical numbers) and publishes `wave` (WaveState), `output` (GyroOutput) and `imu/data_raw`
// (sensor_msgs/Imu, REP-145). It also subscribes `precession/state` (PrecessionState, from a driver
// whose gyro has a precession loop): core::PrecessionWatch, the rule `hrg_bag process` applies too,
// flags the outputs over which the loop turned the wave (FLAG_PRECESSING; their Imu carries the
// "not measured" z variance), holding an output until that stream has reached its stamp. `~reload` (std_srvs/Trigger)
// re-reads and validates
// `~parameter_file` and swaps the model between two samples; a bad file is refused with the reason
// and the old model stays. `~capture_bias` (std_srvs/Trigger) averages the output of a still gyro
// and refreshes D0 (core::BiasCapture), optionally writing the file. Health goes to /diagnostics
// through diagnostic_updater; private parameters are read through a ParameterReader, which warns
// about unknown ones.
#pragma once

#include <diagnostic_updater/diagnostic_updater.h>
#include <diagnostic_updater/update_functions.h>
#include <ros/ros.h>
#include <std_srvs/Trigger.h>

#include <atomic>
#include <condition_variable>
#include <deque>
#include <memory>
#include <mutex>
#include <string>

#include "hrg_gyro/ChannelAmplitudes.h"
#include "hrg_gyro/GyroOutput.h"
#include "hrg_gyro/PrecessionState.h"
#include "hrg_gyro/core/processing/bias_capture.h"
#include "hrg_gyro/core/processing/gyro_processor.h"
#include "hrg_gyro/core/processing/precession_watch.h"
#include "hrg_gyro/core/processing/rate_noise_estimator.h"
#include "hrg_gyro/ros/input_thread.h"
#include "hrg_gyro/ros/parameter_reader.h"
#include "hrg_gyro/ros/reload_record.h"

namespace hrg_gyro {

class ProcessorRos {
 public:
  /// Throws std::exception when ~parameter_file is missing or invalid at start-up.
  ProcessorRos(ros::NodeHandle nh, ros::NodeHandle pnh);
  ~ProcessorRos();

  /// The private parameters as read at start-up (unknown and defaulted keys).
  const ParameterReader& parameters() const { return params_; }
  /// ~shutdown_when_idle, s of wall time (0: never): the node's main ends the node once idleFor() it.
  double shutdownWhenIdle() const { return shutdown_when_idle_; }
  /// True once a channel sample was processed and none since for `seconds` of wall time (the input
  /// queue drained: a lagging processor is not idle).
  bool idleFor(double seconds);

 private:
  void onChannels(const ChannelAmplitudes::ConstPtr& msg);
  void onPrecession(const PrecessionState::ConstPtr& msg);
  /// Publishes, in order, the outputs the precession watch has decided (caller holds the mutex).
  void releaseOutputs();
  bool onReload(std_srvs::Trigger::Request& req, std_srvs::Trigger::Response& res);
  bool onCaptureBias(std_srvs::Trigger::Request& req, std_srvs::Trigger::Response& res);
  void diagnoseInput(diagnostic_updater::DiagnosticStatusWrapper& stat);
  void diagnoseWave(diagnostic_updater::DiagnosticStatusWrapper& stat);
  void diagnoseModel(diagnostic_updater::DiagnosticStatusWrapper& stat);
  void diagnosePrecession(diagnostic_updater::DiagnosticStatusWrapper& stat);
  /// ~wait_for_subscribers: the channels are subscribed once wave and output have their listeners.
  bool outputsListened() const;
  void subscribeChannels();
  void onWaitTimer(const ros::WallTimerEvent& event);
  /// Publishes ~model for the model now in force; `since` is the last stamp of the previous one.
  void publishModel(const ros::Time& since);

  ros::NodeHandle nh_, pnh_;
  ParameterReader params_;
  std::mutex mutex_;  // the model swap and the samples (nodelets may run callbacks concurrently)
  std::unique_ptr<core::GyroProcessor> processor_;
  std::string parameter_file_;
  std::string frame_id_;
  bool publish_imu_ = true;
  core::RateNoiseEstimator rate_noise_;  // the Imu's z variance
  double stall_timeout_ = 0.5;
  double shutdown_when_idle_ = 0.0;
  double quadrature_warn_ = 0.1;

  InputThread input_;  // serves channels_sub_ and precession_sub_ (one thread: in arrival order)
  ros::Subscriber channels_sub_, precession_sub_;
  int queue_size_ = 50000;
  int wait_wave_ = 0, wait_output_ = 0;
  double wait_timeout_ = 0.0;  // s of wall time; <= 0: as long as it takes
  ros::WallTime wait_start_;
  double next_wait_note_ = 10.0;
  ros::WallTimer wait_timer_;
  std::atomic<bool> listening_{false};  // channels subscribed
  ros::Publisher wave_pub_, output_pub_, imu_pub_, model_pub_;
  ros::Time last_stamp_;
  ros::ServiceServer reload_srv_, capture_srv_;

  // Turn-on bias capture (one at a time; the service waits on capture_cv_ for the input thread).
  core::BiasCaptureSettings bias_settings_;
  bool bias_capture_save_ = false;
  double bias_capture_timeout_ = 35.0;  // s of wall time
  std::unique_ptr<core::BiasCapture> capture_;
  std::condition_variable capture_cv_;
  std::uint64_t bias_captures_ = 0;
  std::string last_bias_capture_;

  diagnostic_updater::Updater updater_;
  ros::WallTimer diagnostics_timer_;
  double expected_rate_ = 200.0;
  double min_rate_ = 0.0, max_rate_ = 0.0;
  std::unique_ptr<diagnostic_updater::FrequencyStatus> frequency_;
  std::unique_ptr<diagnostic_updater::TimeStampStatus> stamps_;

  // Health since the last diagnostics report.
  ros::Time last_input_;
  ros::WallTime last_input_wall_;  // a stopped /clock must not hide a stall
  bool seen_input_ = false;
  std::uint32_t last_seq_ = 0;
  std::uint64_t dropped_ = 0, dropped_reported_ = 0;
  core::ProcessorCounters reported_;
  ReloadRecord reload_{"processor", "model"};
  core::WaveState last_wave_;
  bool has_wave_ = false;
  std::uint8_t last_flags_ = 0;

  // The precession loop's state and the outputs waiting for it (all under mutex_).
  core::PrecessionWatch precession_;
  struct PendingOutput {
    GyroOutput::Ptr output;
    core::AngleIncrement increment;
  };
  std::deque<PendingOutput> pending_;        // in the watch's order
  core::Nanoseconds previous_accepted_ = 0;  // the processor's previous accepted stamp: an output's start
  PrecessionState last_precession_;          // the latest record taken, for the diagnostic
  core::PrecessionWatchCounters reported_precession_;
  bool precessing_ = false;  // the last output decided was flagged (for the log's transitions)
};

}  // namespace hrg_gyro
