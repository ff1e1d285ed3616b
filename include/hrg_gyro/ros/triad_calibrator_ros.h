// ROS wrapper of the triad calibration: the calibrator node and the hrg_gyro/Calibrator nodelet run
// it instead of CalibratorRos when `~method` is `triad` (see selected()).
//
// Three gyros in a fixture on the rate table: each axis's processor (namespace = the axis's name in
// the triad file) publishes `<axis>/wave`; the bench publishes `turntable/state` and
// `fixture/position`. The five streams are put back in stamp order (core::TriadFeed, `~stream_hold`)
// and fed to a core::TriadCalibration exactly as `hrg_bag calibrate --method triad` feeds it from a
// bag. A run starts at start-up (`~autostart`) or on `~start`, and finishes on `~finish` or by itself
// once every axis has pointed along the table axis in a locked position and the fixture has then
// stayed released for `~auto_finish_idle` s of stream time. On finish: the report (always, atomically)
// -> when accepted and `~write`: the three axes' parameter files and the triad file, as one checked
// set (previous ones kept as .bak) -> every `~reload_services` entry called, off the callback threads
// -> `~result` (hrg_gyro/TriadCalibrationResult, latched). Every file written lies inside
// `~output_directory`. Parameters: config/calibrator.yaml (its Triad block) and docs/ros_api.md.
#pragma once

#include <diagnostic_updater/diagnostic_updater.h>
#include <ros/ros.h>
#include <std_srvs/Trigger.h>

#include <array>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "hrg_gyro/FixturePosition.h"
#include "hrg_gyro/StartCalibration.h"
#include "hrg_gyro/TriadCalibrationResult.h"
#include "hrg_gyro/TurntableState.h"
#include "hrg_gyro/WaveState.h"
#include "hrg_gyro/core/calibration/triad/triad_feed.h"
#include "hrg_gyro/ros/calibrator_services.h"
#include "hrg_gyro/ros/input_thread.h"
#include "hrg_gyro/ros/job_worker.h"
#include "hrg_gyro/ros/parameter_reader.h"

namespace hrg_gyro {

class TriadCalibratorRos {
 public:
  /// Throws std::exception (naming the parameter) for invalid settings, a missing or unreadable
  /// triad file or axis parameter file, or a file to write outside ~output_directory.
  TriadCalibratorRos(ros::NodeHandle nh, ros::NodeHandle pnh);
  ~TriadCalibratorRos();

  /// True when the calibrator in `pnh` is configured for the triad (~method: triad).
  static bool selected(const ros::NodeHandle& pnh);

  const ParameterReader& parameters() const { return params_; }

 private:
  void onWave(int axis, const WaveState::ConstPtr& msg);
  void onTurntable(const TurntableState::ConstPtr& msg);
  void onFixture(const FixturePosition::ConstPtr& msg);
  bool onStart(StartCalibration::Request& req, StartCalibration::Response& res);
  bool onFinish(std_srvs::Trigger::Request& req, std_srvs::Trigger::Response& res);
  bool onAbort(std_srvs::Trigger::Request& req, std_srvs::Trigger::Response& res);
  void diagnose(diagnostic_updater::DiagnosticStatusWrapper& stat);

  // The constructor's parts, in its order (each throws naming the parameter):
  /// The calibration settings (and the single-axis keys this mode does not use).
  void readSettings();
  /// ~triad_file and its axes, each axis's ~axis_parameter_files entry.
  void readFiles();
  /// ~report_file, ~output_directory (every file to write inside it, all distinct), ~write.
  void readOutputs();
  /// ~reload_services, "{axis}" expanded for each axis.
  void readReloadServices();
  /// Publishers, subscriptions, services, diagnostics, then the threads.
  void serve(int queue_size, double heap_trim_period, bool autostart);

  /// A run on the files as they are now (the priors); throws std::runtime_error naming a bad one.
  std::unique_ptr<core::TriadFeed> newFeed() const;
  /// Starts a new run (newFeed); false + reason when the files cannot be read.
  bool startRun(std::string* reason);
  /// After a record: finishes the run when the feed says so. Caller holds the mutex.
  void maybeFinish();
  /// Fits, reports, writes, hands the reloads and the result to the worker. Caller holds the mutex.
  bool finishRun(std::string* message);
  /// The worker: calls the reload services, then publishes the result, off the callback threads.
  struct Pending {
    TriadCalibrationResult result;
    bool reload = false;
  };
  void serveResult(Pending& p);  // the reloads a written result asks for, then the result published

  ros::NodeHandle nh_, pnh_;
  ParameterReader params_;
  std::mutex mutex_;  // the run and the node's state; never held while calling a service
  core::CalibrationSettings axis_settings_;
  core::TriadCalibrationSettings triad_settings_;
  core::TriadFeedSettings feed_settings_;
  std::string triad_file_, report_file_, output_directory_;
  std::array<std::string, 3> axes_, axis_files_;
  std::vector<std::string> reload_services_;
  bool write_ = true;
  std::unique_ptr<core::TriadFeed> feed_;  // the run in progress (null: idle)
  std::uint64_t runs_ = 0, restarts_before_ = 0;
  std::string last_result_;
  bool last_written_ = false;
  // Counted here, before the feed: messages the run could not take (no run in progress).
  std::uint64_t idle_records_ = 0;
  // ~progress (std_msgs/Time): up to which stamp every stream (axes x, y, z, table, fixture + 1 s)
  // is taken in; under mutex_. A callback notes its record's stamp and publishes on the way out.
  ros::Publisher progress_pub_;
  std::array<ros::Time, 5> latest_in_;
  ros::Time last_progress_;
  int pending_reloads_ = 0;  // written results whose reloads are not done yet
  void publishProgress();
  struct ProgressGuard {
    ProgressGuard(TriadCalibratorRos* c, ros::Time* latest, const ros::Time& stamp) : calibrator(c) { *latest = stamp; }
    ~ProgressGuard() { calibrator->publishProgress(); }
    TriadCalibratorRos* calibrator;
  };
  // The feed's counters survive its run for the diagnostics.
  std::array<core::TriadStreamCounters, core::TriadFeed::kStreamCount> last_counters_{};

  InputThread input_;
  std::array<ros::Subscriber, 3> wave_subs_;
  ros::Subscriber turntable_sub_, fixture_sub_;
  ros::Publisher result_pub_;
  CalibratorServices services_;  // ~start, ~finish, ~abort
  diagnostic_updater::Updater updater_;
  ros::WallTimer diagnostics_timer_;

  JobWorker<Pending> result_worker_;  // reloads and publishes each result off the callback threads
};

}  // namespace hrg_gyro
