// ROS wrapper of the calibration (node calibrator, nodelet hrg_gyro/Calibrator).
//
// Listens to `turntable/state` and `wave` (and, for the correction matrix, to the raw `channels`
// and the generator reference on `truth`) and feeds a core::CalibrationSession. A run starts at
// start-up (`~autostart`) or on `~start`; it finishes on `~finish` or by itself once its data are
// complete and the table has rested for `~auto_finish_idle` s. The outcome is published latched on
// `~result`; when every quality gate passes, the parameter file is rewritten atomically (previous
// kept as .bak), a report is written next to it and the processor's `~reload` is called. `~stages`
// runs several methods in a row: [correction_matrix, dual_rate] is the paper's two-stage
// refinement (P first, then the residual K and D measured through the new P). The calibration
// itself is the core's: the stages and reports' names (core::StagedCalibration), the routing of every
// input record into the run (core::CalibrationFeed, as hrg_bag calibrate and the offline pipeline
// route theirs) and the field method's plan (core::FieldPlanRun); this class wires them to ROS.
//
// The field method (a still gyro, no table) reads `precession/state` in place of `turntable/state`
// and commands the virtual rotation itself: it publishes core::fieldCommandPlan's commands on
// `command/precession` as the gyro's own stream time (the precession state's stamps) passes, and a
// rate of 0 when the run ends before the plan does. core::FieldPlanRun::step judges each precession
// state and says what is due: a command this run did not send aborts the run (nothing written, the
// reason on ~result), and a plan that is over without complete data refuses it instead of waiting.
#pragma once

#include <diagnostic_updater/diagnostic_updater.h>
#include <ros/ros.h>
#include <std_srvs/Trigger.h>

#include <memory>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

#include "hrg_gyro/ChannelAmplitudes.h"
#include "hrg_gyro/GroundTruth.h"
#include "hrg_gyro/PrecessionState.h"
#include "hrg_gyro/StartCalibration.h"
#include "hrg_gyro/TurntableState.h"
#include "hrg_gyro/WaveState.h"
#include "hrg_gyro/core/calibration/calibration_feed.h"
#include "hrg_gyro/core/calibration/field_command_plan.h"
#include "hrg_gyro/core/calibration/staged_calibration.h"
#include "hrg_gyro/ros/calibrator_services.h"
#include "hrg_gyro/ros/input_thread.h"
#include "hrg_gyro/ros/job_worker.h"
#include "hrg_gyro/ros/parameter_reader.h"

namespace hrg_gyro {

class CalibratorRos {
 public:
  /// Throws std::exception for invalid settings or an unreadable prior parameter file.
  CalibratorRos(ros::NodeHandle nh, ros::NodeHandle pnh);
  ~CalibratorRos();

  /// The private parameters as read at start-up (unknown and defaulted keys).
  const ParameterReader& parameters() const { return params_; }

  /// A field run's virtual rotation stopped (rate 0 commanded) if it is under way: the node calls it
  /// on SIGINT before ROS shuts down, the destructor in any case (a nodelet unloaded).
  void stopVirtualRotation(const char* why);

 private:
  // The constructor's parts: the calibration settings; the files (parameter file, report, output
  // directory; the prior read once); the stages; the topics (and the model beside the reload service).
  void readSettings();
  void readOutputPaths();
  void readStages();
  void subscribe(int queue_size);

  void onTurntable(const TurntableState::ConstPtr& msg);
  void onPrecession(const PrecessionState::ConstPtr& msg);
  void onWave(const WaveState::ConstPtr& msg);
  void onChannels(const ChannelAmplitudes::ConstPtr& msg);
  void onTruth(const GroundTruth::ConstPtr& msg);
  /// What a record fed asks for (feed_): a warning for a sweep given up, a restarted run noted, the
  /// run finished.
  void handle(const core::FeedStep& step);
  /// Field method: one precession state of the plan (FieldPlanRun::step): the commands due sent, the
  /// run aborted for a command it did not send, or finished refused when the plan is overdue.
  void advanceFieldPlan(const core::PrecessionReport& state);
  /// Field method: the run is aborted, nothing written (no file, no report), `outcome` published.
  void abortFieldRun(core::CalibrationOutcome outcome);
  /// Field method: a run that ends (finished, aborted, restarted) before its plan stops the rotation.
  void stopFieldPlan(const char* why);
  void publishPrecession(double rate);
  bool fieldRun() { return session() && core::traitsOf(session()->settings().method).virtual_rotation; }
  bool onStart(StartCalibration::Request& req, StartCalibration::Response& res);
  bool onFinish(std_srvs::Trigger::Request& req, std_srvs::Trigger::Response& res);
  bool onAbort(std_srvs::Trigger::Request& req, std_srvs::Trigger::Response& res);
  void diagnose(diagnostic_updater::DiagnosticStatusWrapper& stat);

  /// The session restarted its run (a stream went back for good, settings backward_reset and
  /// jump_persist): counted, and the node's run state (skipped waves, the field plan) starts over.
  void noteRestart();
  /// Starts the next stage with the current parameter file as prior; false + reason on failure
  /// (then no stage is left).
  bool startRun(std::string* reason);
  core::CalibrationSession* session() { return calibration_->session(); }
  /// Fits, gates, writes, publishes, reloads; returns the outcome. Caller holds the mutex. With a
  /// `refusal` (gate, message), the run is refused for it whatever the fit's gates say.
  core::CalibrationOutcome finishRun(bool* written, std::string* message,
                                     const std::pair<std::string, std::string>& refusal = {});
  struct ReloadRequest {
    bool start_next = false;  // start the next stage once the processor runs the new file
    std::string calibration;  // the file's calibration method and time, to recognise its ModelInfo
  };
  /// The reload worker's job: calls the processor's ~reload off the callback threads, then starts
  /// the next stage if there is one (it must see the wave through the new model).
  void reload(const ReloadRequest& request);

  ros::NodeHandle nh_, pnh_;
  ParameterReader params_;
  std::mutex mutex_;  // session and state; never held while calling a service
  core::CalibrationSettings base_settings_;
  std::unique_ptr<core::StagedCalibration> calibration_;  // the stages and the run in progress
  // Every input record goes through it into the run in progress (pointed at each run's session by
  // startRun; used only while session() is not null).
  core::CalibrationFeed feed_;
  std::string parameter_file_, report_file_, output_directory_, reload_service_;
  bool write_ = true;
  std::uint64_t runs_ = 0;
  std::string last_result_;
  // Bag loops: counted here, detected by the session.
  std::uint64_t resets_ = 0, reported_resets_ = 0;
  bool last_accepted_ = false;

  InputThread input_;  // serves the five subscriptions below
  ros::Subscriber turntable_sub_, wave_sub_, channels_sub_, truth_sub_, precession_sub_;
  ros::Publisher result_pub_;
  // ~progress (std_msgs/Time): up to which stamp both streams are taken in (publishProgress); under
  // mutex_. A callback notes its record's stamp and publishes on the way out (ProgressGuard).
  ros::Publisher progress_pub_;
  ros::Time last_wave_in_, last_rotation_in_, last_progress_;
  int pending_reloads_ = 0;  // written results whose processor reload is not done yet
  void publishProgress();
  struct ProgressGuard {
    ProgressGuard(CalibratorRos* c, ros::Time* latest, const ros::Time& stamp) : calibrator(c) { *latest = stamp; }
    ~ProgressGuard() { calibrator->publishProgress(); }
    CalibratorRos* calibrator;
  };
  ros::Publisher command_pub_;  // command/precession, the field method's virtual rotation

  // The field method's plan under way (under mutex_).
  core::FieldPlanRun field_run_;
  std::uint64_t field_commands_sent_ = 0;
  CalibratorServices services_;
  diagnostic_updater::Updater updater_;
  ros::WallTimer diagnostics_timer_;

  // The processor's ModelInfo (latched): header.stamp is the last input stamp processed under the
  // previous model, so a stage that must see the wave through the new model skips waves up to it.
  ros::Subscriber model_sub_;
  std::string model_calibration_;  // method + time of the latest ModelInfo (under the reload worker's lock)
  ros::Time model_since_;
  ros::Time skip_waves_until_;  // under mutex_
  std::uint64_t skipped_old_model_ = 0;
  JobWorker<ReloadRequest> reload_worker_;  // last: stopped (joined) first
};

}  // namespace hrg_gyro
