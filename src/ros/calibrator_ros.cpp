#include "hrg_gyro/ros/calibrator_ros.h"

#include <std_msgs/Time.h>

#include <chrono>
#include <cmath>

#include "hrg_gyro/CalibrationResult.h"
#include "hrg_gyro/ModelInfo.h"
#include "hrg_gyro/PrecessionCommand.h"
#include "hrg_gyro/core/calibration/triad/triad_calibration.h"
#include "hrg_gyro/core/common/atomic_file.h"
#include "hrg_gyro/core/common/output_directory.h"
#include "hrg_gyro/core/model/parameter_file.h"
#include "hrg_gyro/ros/calibrator_node_keys.h"
#include "hrg_gyro/ros/conversions.h"
#include "hrg_gyro/ros/output_directory_check.h"
#include "hrg_gyro/ros/param_tree.h"

namespace hrg_gyro {
namespace {

using diagnostic_msgs::DiagnosticStatus;

}  // namespace

CalibratorRos::CalibratorRos(ros::NodeHandle nh, ros::NodeHandle pnh)
    : nh_(nh),
      pnh_(pnh),
      params_(pnh, "calibrator"),
      feed_(nullptr, nullptr, true),
      updater_(nh, params_.checkDiagnosticPeriod(), pnh.getNamespace()) {
  readSettings();
  readOutputPaths();
  readStages();
  // As the processor's: seconds of backlog at 10 kHz.
  const int queue_size = params_.getAtLeast("queue_size", 50000, 1, "messages");
  const double heap_trim_period = params_.getFinite("heap_trim_period", 10.0, "s; <= 0: never");
  const bool autostart = params_.get("autostart", true);
  params_.warnAboutUnknownKeys();

  subscribe(queue_size);
  services_ =
      CalibratorServices(pnh_, this, &CalibratorRos::onStart, &CalibratorRos::onFinish, &CalibratorRos::onAbort);
  diagnostics_timer_ = startCalibratorDiagnostics(
      nh_, updater_, "calibration", [this](diagnostic_updater::DiagnosticStatusWrapper& s) { diagnose(s); },
      heap_trim_period);
  if (autostart) {
    std::lock_guard<std::mutex> lock(mutex_);
    std::string reason;
    if (!startRun(&reason)) throw std::runtime_error("calibrator: " + reason);
  }
  // Threads last: a constructor that throws must not leave a joinable thread behind.
  reload_worker_.start([this](ReloadRequest& request) { reload(request); });
  input_.start();
}

void CalibratorRos::readSettings() {
  base_settings_ =
      core::CalibrationSettings::parse(core::YamlField(privateParameters(pnh_), ""), calibratorNodeOnlyKeys());
  params_.claim(core::CalibrationSettings::keyPaths());
  params_.claim(core::CalibrationSettings::formerKeyPaths(), true);  // read when set, never a default
  // The triad mode's keys (TriadCalibratorRos reads them): shared template, not used by one axis.
  std::vector<std::string> triad_keys{"triad_file", "reload_services", "stream_hold"};
  for (const std::string& k : core::TriadCalibrationSettings::keys()) triad_keys.push_back("triad/" + k);
  params_.claim(triad_keys);
  params_.claim({"axis_parameter_files"}, true);  // a map; the template's {} is no parameter at all
  if (!params_.get<std::string>("triad_file", "").empty()) {
    ROS_WARN("calibrator: ~triad_file is read in triad mode only (~method: triad); method %s ignores it",
             core::nameOf(base_settings_.method).c_str());
  }
}

void CalibratorRos::readOutputPaths() {
  parameter_file_ = params_.get<std::string>("parameter_file", "");
  if (parameter_file_.empty())
    throw std::invalid_argument("calibrator: ~parameter_file is required (the file to refresh)");
  // Empty report file and output directory: derived from the parameter file.
  report_file_ = params_.get<std::string>("report_file", "");
  if (report_file_.empty()) report_file_ = core::StagedCalibration::defaultReportPath(parameter_file_);
  // Every file the calibrator writes stays in one directory (by default that of the parameter file).
  output_directory_ = params_.get<std::string>("output_directory", "");
  if (output_directory_.empty()) output_directory_ = core::directoryOf(parameter_file_);
  reload_service_ = params_.get<std::string>("reload_service", "processor/reload");
  write_ = params_.get("write", write_);
  for (const std::string& f : {parameter_file_, report_file_}) {
    const std::string outside = outsideOutputDirectory(f, output_directory_);
    if (!outside.empty()) throw std::invalid_argument("calibrator: " + outside);
  }
  core::loadParameterFile(parameter_file_);  // fail early on a bad prior
}

void CalibratorRos::readStages() {
  std::vector<std::string> stage_names;
  std::vector<core::CalibrationMethodKind> stages;
  params_.getOptional("stages", &stage_names);
  for (const std::string& m : stage_names) {
    try {
      stages.push_back(core::parseCalibrationMethod(m));
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(std::string("calibrator: ~stages: ") + e.what());
    }
  }
  calibration_ = std::make_unique<core::StagedCalibration>(base_settings_, stages);
}

void CalibratorRos::subscribe(int queue_size) {
  result_pub_ = pnh_.advertise<CalibrationResult>("result", 1, true);
  progress_pub_ = pnh_.advertise<std_msgs::Time>("progress", 10);
  ros::NodeHandle in = input_.handle(nh_);
  // The wave first: a driver waiting for a turntable listener then starts after this subscription
  // exists (in a nodelet manager the two are a poll of the driver apart).
  wave_sub_ = in.subscribe("wave", queue_size, &CalibratorRos::onWave, this, ros::TransportHints().tcpNoDelay());
  // The field method's streams: the precession loop's state in, its commands out (for every method,
  // since ~start may choose field; a driver without the loop publishes no state).
  precession_sub_ = in.subscribe("precession/state", queue_size, &CalibratorRos::onPrecession, this,
                                 ros::TransportHints().tcpNoDelay());
  // Latched: a driver that reconnects (or starts late) gets the command in force, rate 0 after a stop.
  command_pub_ = nh_.advertise<PrecessionCommand>("command/precession", 10, true);
  if (calibration_->usesGeneratorPairs()) {
    channels_sub_ =
        in.subscribe("channels", queue_size, &CalibratorRos::onChannels, this, ros::TransportHints().tcpNoDelay());
    truth_sub_ = in.subscribe("truth", queue_size, &CalibratorRos::onTruth, this, ros::TransportHints().tcpNoDelay());
  }
  turntable_sub_ = in.subscribe("turntable/state", queue_size, &CalibratorRos::onTurntable, this,
                                ros::TransportHints().tcpNoDelay());
  if (reload_service_.empty()) return;
  // The processor's model topic sits beside its reload service (processor/reload -> processor/model).
  std::string model_topic = reload_service_;
  const std::size_t slash = model_topic.rfind('/');
  model_topic = (slash == std::string::npos ? std::string() : model_topic.substr(0, slash + 1)) + "model";
  model_sub_ = nh_.subscribe<ModelInfo>(model_topic, 10, [this](const ModelInfo::ConstPtr& m) {
    reload_worker_.update([&] {
      model_calibration_ = m->calibration_method + " " + m->calibration_time;
      model_since_ = m->header.stamp;
    });
  });
}

CalibratorRos::~CalibratorRos() {
  // First: the timer runs the diagnostic tasks, some of them members destroyed before it (a
  // FrequencyStatus called after its destruction aborted a test with "pure virtual method called").
  diagnostics_timer_.stop();
  stopVirtualRotation("the calibrator shut down");
  turntable_sub_.shutdown();
  wave_sub_.shutdown();
  channels_sub_.shutdown();
  truth_sub_.shutdown();
  precession_sub_.shutdown();
  input_.stop();
  reload_worker_.stop();
}

void CalibratorRos::reload(const ReloadRequest& request) {
  bool reloaded = reload_service_.empty();
  if (!reloaded) {
    const std::string service = nh_.resolveName(reload_service_);
    std_srvs::Trigger call;
    if (ros::service::waitForService(service, ros::Duration(5.0)) && ros::service::call(service, call)) {
      reloaded = call.response.success;
      if (reloaded) {
        ROS_INFO("calibrator: processor reloaded: %s", call.response.message.c_str());
      } else {
        ROS_ERROR("calibrator: processor refused the new file: %s", call.response.message.c_str());
      }
    } else {
      ROS_ERROR("calibrator: could not call %s", service.c_str());
    }
  }
  if (!(request.start_next && reloaded)) {
    std::lock_guard<std::mutex> lock(mutex_);
    --pending_reloads_;
    publishProgress();  // the driver may be waiting for it with no data left in flight
    return;
  }
  // Waves already queued (here or in transit) went through the previous model: the next stage
  // must not see them. The processor's ModelInfo for this file says up to which stamp.
  ros::Time since;
  bool known = false;
  if (model_sub_) {
    known = reload_worker_.waitUntil(std::chrono::seconds(5), [&] {
      since = model_since_;
      return model_calibration_ == request.calibration;
    });
  }
  if (!known) {
    ROS_WARN(
        "calibrator: no ModelInfo from the processor for the new file: the next stage may see waves "
        "still queued from the previous model");
  }
  std::lock_guard<std::mutex> lock(mutex_);
  std::string reason;
  if (calibration_->hasNextStage() && startRun(&reason) && known) {
    skip_waves_until_ = since;
  }
  --pending_reloads_;
  publishProgress();
}

bool CalibratorRos::startRun(std::string* reason) {
  const std::string method = core::nameOf(calibration_->nextStage());
  try {
    calibration_->startNextStage(core::loadParameterFile(parameter_file_));
    skip_waves_until_ = ros::Time();
    feed_.startRun(session());
    field_run_ = core::FieldPlanRun();
    if (fieldRun()) {
      // Nothing is commanded for a plan that cannot run or cannot pass (too long; a loop lag at the
      // rate above field/max_drift_std for a gyro whose resonator is given).
      field_run_ = core::FieldPlanRun(session()->settings(), ros::this_node::getName());
      ROS_INFO(
          "calibrator: field: %zu segments at %g rad/s planned over %.1f s of stream time, from the first "
          "precession state while the driver listens on %s",
          session()->settings().field.directions.size(), session()->settings().field.rate,
          field_run_.plan().back().time, command_pub_.getTopic().c_str());
    }
    ROS_INFO("calibrator: %s run started (prior %s)", method.c_str(), parameter_file_.c_str());
    return true;
  } catch (const std::exception& e) {
    *reason = std::string("cannot start ") + method + ": " + e.what();
    ROS_ERROR("calibrator: %s", reason->c_str());
    calibration_->abort();
    return false;
  }
}

void CalibratorRos::handle(const core::FeedStep& step) {
  if (step.sweep_given_up) {
    ROS_WARN(
        "calibrator: the raw channels did not reach the end of the generator sweep within %.0f s; "
        "fitting P with the %llu pairs received",
        core::CalibrationFeed::kSweepChannelsWait, static_cast<unsigned long long>(session()->counters().used));
  }
  if (step.restarted) noteRestart();
  if (step.should_finish) {
    bool written = false;
    std::string message;
    finishRun(&written, &message);
  }
}

void CalibratorRos::noteRestart() {
  // The session saw a stream go back for good (a looping bag, a restarted driver) and started the
  // run over from its prior; what the node keeps about the run starts over too (the feed's own state
  // has).
  ++resets_;
  ROS_WARN("calibrator: time went back for %d records in a row (bag loop?): %s run restarted",
           base_settings_.jump_persist, core::nameOf(session()->settings().method).c_str());
  skip_waves_until_ = ros::Time();
  if (!field_run_.empty()) {
    // The field plan starts over with the run, from the next precession state.
    stopFieldPlan("its run restarted");
    field_run_.restart();
  }
}

void CalibratorRos::publishPrecession(double rate) {
  PrecessionCommand command;
  command.header.stamp = ros::Time::now();
  command.rate = rate;
  command_pub_.publish(command);
  ++field_commands_sent_;
}

void CalibratorRos::advanceFieldPlan(const core::PrecessionReport& state) {
  const core::FieldPlanStep step = field_run_.step(
      state, [this] { return command_pub_.getNumSubscribers() > 0; }, *session(), feed_.newestWave());
  if (!step.foreign.empty()) {
    core::CalibrationOutcome o;
    o.method = session()->settings().method;
    core::refuseFieldRun(&o, "precession_command", step.foreign);
    abortFieldRun(o);
    return;
  }
  for (std::size_t i = 0; i < step.due.size(); ++i) {
    const core::PlannedPrecession& p = step.due[i];
    publishPrecession(p.rate);
    ROS_INFO("calibrator: field: virtual rotation at %g rad/s commanded (%zu of %zu, %.1f s into the plan)", p.rate,
             field_run_.sent() - step.due.size() + i + 1, field_run_.plan().size(), p.time);
  }
  if (!step.overdue.empty()) {
    bool written = false;
    std::string message;
    finishRun(&written, &message, {"plan", step.overdue});
  }
}

void CalibratorRos::stopVirtualRotation(const char* why) {
  std::lock_guard<std::mutex> lock(mutex_);
  stopFieldPlan(why);
}

void CalibratorRos::stopFieldPlan(const char* why) {
  // Between its first and its last command the plan has the wave turning: stop it.
  if (!field_run_.end()) return;
  publishPrecession(0.0);
  ROS_WARN("calibrator: field: virtual rotation stopped (rate 0 commanded): %s before the plan's end", why);
}

void CalibratorRos::abortFieldRun(core::CalibrationOutcome outcome) {
  stopFieldPlan("the run was aborted");
  calibration_->abort();
  result_pub_.publish(toMessage(outcome, false, parameter_file_, ros::Time::now()));
  ++runs_;
  last_accepted_ = false;
  last_result_ = "aborted, nothing written: " + outcome.reason;
  ROS_ERROR("calibrator: field run aborted, nothing written: %s", outcome.reason.c_str());
}

void CalibratorRos::onTurntable(const TurntableState::ConstPtr& msg) {
  std::lock_guard<std::mutex> lock(mutex_);
  ProgressGuard progress(this, &last_rotation_in_, msg->header.stamp);
  if (!session()) return;  // a field run's rotation is the precession loop's: the feed ignores the table's
  handle(feed_.addTableState(toNanoseconds(msg->header.stamp), msg->angle, msg->rate, msg->header.seq));
}

void CalibratorRos::onPrecession(const PrecessionState::ConstPtr& msg) {
  std::lock_guard<std::mutex> lock(mutex_);
  ProgressGuard progress(this, &last_rotation_in_, msg->header.stamp);
  if (!fieldRun()) return;
  handle(feed_.addPrecessionState(toNanoseconds(msg->header.stamp), msg->angle, msg->rate, msg->header.seq));
  if (!session()) return;  // finished on this record
  advanceFieldPlan({toNanoseconds(msg->header.stamp), msg->rate, msg->commands, msg->source});
}

void CalibratorRos::onWave(const WaveState::ConstPtr& msg) {
  std::lock_guard<std::mutex> lock(mutex_);
  ProgressGuard progress(this, &last_wave_in_, msg->header.stamp);
  if (!session()) return;
  if (!skip_waves_until_.isZero() && msg->header.stamp <= skip_waves_until_) {
    ++skipped_old_model_;
    return;
  }
  handle(feed_.addWave(toNanoseconds(msg->header.stamp), msg->theta, msg->frequency,
                       core::quadratureRatio(msg->quadrature, msg->amplitude)));
}

void CalibratorRos::onChannels(const ChannelAmplitudes::ConstPtr& msg) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (session()) handle(feed_.addChannels(fromMessage(*msg)));
}

void CalibratorRos::onTruth(const GroundTruth::ConstPtr& msg) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!session()) return;
  const core::Nanoseconds stamp = toNanoseconds(msg->header.stamp);
  handle(msg->generator ? feed_.addReference(stamp, {msg->amplitude, msg->quadrature, msg->theta, msg->phase})
                        : feed_.addSweepEnd(stamp));
}

core::CalibrationOutcome CalibratorRos::finishRun(bool* written, std::string* message,
                                                  const std::pair<std::string, std::string>& refusal) {
  stopFieldPlan("the run finished");
  core::CalibrationOutcome o = calibration_->finishStage();
  if (!refusal.first.empty()) core::refuseFieldRun(&o, refusal.first, refusal.second);
  *written = false;
  if (o.accepted && write_) {
    try {
      o.parameters.calibration.source = "live";
      core::saveParameterFile(parameter_file_, o.parameters);
      *written = true;
      *message = "accepted and written to " + parameter_file_;
    } catch (const std::exception& e) {
      *message = std::string("accepted but not written: ") + e.what();
      o.reason = *message;
    }
  } else {
    *message = o.accepted ? "accepted, not written (~write is false)" : "refused: " + o.reason;
  }
  {
    const std::string path = core::StagedCalibration::stageReportPath(report_file_, o.method);
    try {
      core::writeFileAtomically(path, core::emitCalibrationReport(o));  // whole or not at all
    } catch (const std::exception& e) {
      ROS_WARN("calibrator: cannot write the report %s: %s", path.c_str(), e.what());
    }
  }
  result_pub_.publish(toMessage(o, *written, parameter_file_, ros::Time::now()));
  ++runs_;
  last_accepted_ = o.accepted && *written;
  last_result_ = *message;
  if (*written && o.field.present) {
    // The field method estimates no K: say what it measured instead.
    ROS_INFO("calibrator: %s %s (D0 %.4g rad/s, virtual rate gain %.7f, K kept from the prior)",
             core::nameOf(o.method).c_str(), message->c_str(), o.drift.empty() ? NAN : o.drift[0].mean,
             o.field.virtual_rate_gain.mean);
  } else if (*written) {
    ROS_INFO("calibrator: %s %s (peak nonlinearity of the new K: %.1f ppm, coverage %.1f %%)",
             core::nameOf(o.method).c_str(), message->c_str(), o.nonlinearity_ppm, 100 * o.coverage);
  } else {
    ROS_WARN("calibrator: %s %s", core::nameOf(o.method).c_str(), message->c_str());
  }
  for (const core::DefectDiagnosis& d : o.diagnosis) {
    ROS_INFO("calibrator: root-cause diagnosis (first order, read against the P in force) %s",
             core::describe(d).c_str());
  }
  const bool more = *written && calibration_->hasNextStage();
  if (*written) {
    reload_worker_.push({more, o.parameters.calibration.method.name() + " " + o.parameters.calibration.time});
    ++pending_reloads_;  // ~progress holds until the processor runs the new file
  }
  return o;
}

void CalibratorRos::publishProgress() {
  // Up to where both streams are taken in (the waves come a hop later, through the processor), at
  // most every 50 ms of stamps; held while the processor is being reloaded, so that a driver pacing
  // itself on it (driver_sim's ~pace_topic) lets no data through the previous model meanwhile.
  if (pending_reloads_ > 0 || last_wave_in_.isZero() || last_rotation_in_.isZero()) return;
  const ros::Time until = std::min(last_wave_in_, last_rotation_in_);
  if (!last_progress_.isZero() && until >= last_progress_ && until < last_progress_ + ros::Duration(0.05)) return;
  last_progress_ = until;
  std_msgs::Time t;
  t.data = until;
  progress_pub_.publish(t);
}

bool CalibratorRos::onStart(StartCalibration::Request& req, StartCalibration::Response& res) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (session()) {
    // Starting over would silently throw away the data gathered so far.
    res.success = false;
    res.message =
        "a run is in progress (" + core::nameOf(session()->settings().method) + "): ~finish or ~abort it first";
    return true;
  }
  if (req.method.empty()) {
    calibration_->rewind();
  } else {
    try {
      calibration_->rewind({core::parseCalibrationMethod(req.method)});
    } catch (const std::invalid_argument& e) {
      res.success = false;
      res.message = e.what();
      return true;
    }
  }
  std::string reason;
  res.success = startRun(&reason);
  res.message = res.success ? "started " + core::nameOf(session()->settings().method) : reason;
  return true;
}

bool CalibratorRos::onFinish(std_srvs::Trigger::Request&, std_srvs::Trigger::Response& res) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!session()) {
    res.success = false;
    res.message = "no calibration run in progress";
    return true;
  }
  bool written = false;
  std::string message;
  finishRun(&written, &message);
  res.success = written;
  res.message = message;
  return true;
}

bool CalibratorRos::onAbort(std_srvs::Trigger::Request&, std_srvs::Trigger::Response& res) {
  std::lock_guard<std::mutex> lock(mutex_);
  res.success = session() != nullptr;
  res.message =
      session() ? "aborted " + core::nameOf(session()->settings().method) + ": nothing written" : "no run in progress";
  stopFieldPlan("the run was aborted");
  calibration_->abort();
  return true;
}

void CalibratorRos::diagnose(diagnostic_updater::DiagnosticStatusWrapper& stat) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (session()) {
    const core::CalibrationProgress p = session()->progress();
    const core::SessionCounters& c = session()->counters();
    if (c.rotation_records == 0 && c.wave > 100) {
      stat.summary(DiagnosticStatus::WARN, fieldRun() ? "wave samples but no precession state: check "
                                                        "precession/state (a driver whose gyro has the loop)"
                                                      : "wave samples but no turntable state: check turntable/state");
    } else if (resets_ > reported_resets_) {
      stat.summaryf(DiagnosticStatus::WARN, "time went backwards: run restarted; %s %.0f %%", p.summary.c_str(),
                    100 * p.fraction);
    } else {
      stat.summaryf(DiagnosticStatus::OK, "%s %.0f %%", p.summary.c_str(), 100 * p.fraction);
    }
    stat.add("method", core::nameOf(session()->settings().method));
    stat.add("progress", p.fraction);
    // The table's stream: a field run's is the precession loop's state.
    const std::string stream = fieldRun() ? "precession" : "turntable";
    stat.add(stream + " states", c.rotation_records);
    stat.add("wave samples", c.wave);
    stat.add("used", c.used);
    stat.add("not on a settled plateau", c.unsettled);
    stat.add("without " + stream + " state", c.unsynchronized);
    stat.add("dropped (out-of-order stamps)", c.out_of_order);
    stat.add("dropped (stamp jumps)", c.wave_jumps);
    // Glitched records of that stream, dropped before the plateau detector (all runs of this session).
    stat.add(stream + " dropped (bad rate)", c.rejected.bad_rate);
    stat.add(stream + " dropped (bad angle)", c.rejected.bad_angle);
    stat.add(stream + " dropped (zero stamp)", c.rejected.bad_stamp);
    stat.add(stream + " dropped (duplicate stamp)", c.rejected.duplicate);
    stat.add(stream + " dropped (out-of-order stamp)", c.rejected.out_of_order);
    stat.add(stream + " dropped (stamp jump)", c.rejected.stamp_jump);
    if (!field_run_.empty()) {
      stat.add("field commands sent", field_commands_sent_);
      stat.add("field commands planned", field_run_.plan().size());
      stat.add("field plan started", field_run_.started());
    }
  } else if (runs_ > 0 && !last_accepted_) {
    stat.summary(DiagnosticStatus::WARN, "idle; last run " + last_result_);
  } else {
    stat.summary(DiagnosticStatus::OK, runs_ > 0 ? "idle; last run " + last_result_ : "idle");
  }
  stat.add("runs", runs_);
  stat.add("restarts (time went backwards)", resets_);
  stat.add("waves skipped (through the previous model)", skipped_old_model_);
  stat.add("parameter file", parameter_file_);
  reported_resets_ = resets_;
}

}  // namespace hrg_gyro
