// Verification of a simulated session (node session_monitor, nodelet hrg_gyro/SessionMonitor).
//
// Pairs each processor `output` with the simulator's `truth` of the same stamp and, on the
// profile segments whose label starts with `~verification_prefix`, measures the compensated output
// against the true inertial angle (core::OutputEvaluator: dual-rate nonlinearity on the output,
// angle error). A second processor fed the uncalibrated model (`before/output`) gives the "before"
// figures. It collects the calibrator's latched `~result`, checks on the processor's latched
// `processor/model` that the calibrated model was in force before the verification began, and
// computes the exact injected model from the driver's scenario parameters. When the driver reports `done`, it writes
// the summary (the same text as hrg_session) to `~summary_file`, publishes the key figures as YAML on `~summary`
// (latched) and, with `~shutdown_when_done`, ends its process (as a nodelet: the manager).
#pragma once

#include <ros/ros.h>
#include <std_msgs/Bool.h>

#include <deque>
#include <memory>
#include <mutex>
#include <string>

#include "hrg_gyro/CalibrationResult.h"
#include "hrg_gyro/GroundTruth.h"
#include "hrg_gyro/GyroOutput.h"
#include "hrg_gyro/ModelInfo.h"
#include "hrg_gyro/core/evaluation/output_evaluator.h"
#include "hrg_gyro/core/simulation/simulation_config.h"
#include "hrg_gyro/ros/parameter_reader.h"

namespace hrg_gyro {

class SessionMonitorRos {
 public:
  SessionMonitorRos(ros::NodeHandle nh, ros::NodeHandle pnh);

 private:
  struct TruthSample {
    core::Nanoseconds stamp;
    double table_rate, inertial_angle, inertial_rate;
    bool verify;  // on a verification segment
  };
  struct OutputSample {
    core::Nanoseconds stamp;
    double theta_mid, alpha;
  };
  struct Track {
    explicit Track(const core::EvaluationSettings& s) : evaluator(s) {}
    core::OutputEvaluator evaluator;
    std::deque<OutputSample> pending;  // outputs whose truth has not arrived yet
    std::uint64_t samples = 0;
    std::uint64_t unmatched = 0;   // verification-span outputs without a truth
    core::Nanoseconds passed = 0;  // every truth up to here has been looked at
  };
  void onTruth(const GroundTruth::ConstPtr& msg);
  void onOutput(const GyroOutput::ConstPtr& msg, Track* track);
  void onResult(const CalibrationResult::ConstPtr& msg);
  void onDone(const std_msgs::Bool::ConstPtr& msg);
  void onModel(const ModelInfo::ConstPtr& msg);
  void match(Track* track);
  void finish();

  ros::NodeHandle nh_, pnh_;
  ParameterReader params_;
  std::mutex mutex_;
  std::string prefix_, summary_file_, prior_file_;
  bool shutdown_when_done_ = false;
  std::unique_ptr<core::SimulationConfig> scenario_;
  core::EvaluationSettings evaluation_;
  std::unique_ptr<Track> after_, before_;
  std::deque<TruthSample> truth_;  // every truth stamp still needed by some track, in order
  CalibrationResult::ConstPtr result_;
  core::Nanoseconds first_verification_stamp_ = 0, last_verification_stamp_ = 0;
  std::uint64_t verification_truths_ = 0;
  core::Nanoseconds model_since_ = -1;  // data stamp from which the calibrated model applies
  bool finished_ = false;
  ros::Subscriber truth_sub_, output_sub_, before_sub_, result_sub_, done_sub_, model_sub_;
  ros::WallTimer finish_timer_;
  ros::WallTime last_input_wall_;                 // the latest truth or output (under mutex_)
  static constexpr double kQuietAfterDone = 5.0;  // s of wall time without input: in-flight ones are in
  ros::Publisher summary_pub_, done_pub_;
};

}  // namespace hrg_gyro
