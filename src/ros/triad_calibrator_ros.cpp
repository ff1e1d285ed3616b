#include "hrg_gyro/ros/triad_calibrator_ros.h"

#include <std_msgs/Time.h>

#include <algorithm>
#include <cstdio>
#include <map>
#include <stdexcept>

#include "hrg_gyro/core/calibration/staged_calibration.h"
#include "hrg_gyro/core/calibration/triad/triad_result_files.h"
#include "hrg_gyro/core/common/atomic_file.h"
#include "hrg_gyro/core/common/output_directory.h"
#include "hrg_gyro/core/model/parameter_file.h"
#include "hrg_gyro/core/model/triad_file.h"
#include "hrg_gyro/ros/calibrator_node_keys.h"
#include "hrg_gyro/ros/calibrator_services.h"
#include "hrg_gyro/ros/conversions.h"
#include "hrg_gyro/ros/output_directory_check.h"
#include "hrg_gyro/ros/param_tree.h"

namespace hrg_gyro {
namespace {

using diagnostic_msgs::DiagnosticStatus;

constexpr const char* kNode = "calibrator (triad)";
// In an entry of ~reload_services, replaced by each axis's name in turn.
constexpr const char* kAxisPlaceholder = "{axis}";

std::invalid_argument error(const std::string& what) { return std::invalid_argument(std::string(kNode) + ": " + what); }

std::string joined(const std::array<std::string, 3>& items) { return items[0] + ", " + items[1] + ", " + items[2]; }

/// A stamp as sec.nsec, exactly (the tests compare it with the last stamp of a bag); "none" for 0.
std::string stampText(core::Nanoseconds t) {
  if (t == 0) return "none";
  char text[32];
  std::snprintf(text, sizeof(text), "%lld.%09lld", static_cast<long long>(t / 1000000000),
                static_cast<long long>(t % 1000000000));
  return text;
}

}  // namespace

bool TriadCalibratorRos::selected(const ros::NodeHandle& pnh) {
  std::string method;
  return pnh.getParam("method", method) && method == core::nameOf(core::CalibrationMethodKind::kTriad);
}

TriadCalibratorRos::TriadCalibratorRos(ros::NodeHandle nh, ros::NodeHandle pnh)
    : nh_(nh), pnh_(pnh), params_(pnh, kNode), updater_(nh, params_.checkDiagnosticPeriod(), pnh.getNamespace()) {
  readSettings();
  readFiles();
  readOutputs();
  readReloadServices();
  feed_settings_.hold = params_.getInRange("stream_hold", feed_settings_.hold, 0.0, 60.0, "s");
  feed_settings_.auto_finish_idle = axis_settings_.auto_finish_idle;
  feed_settings_.stamps = axis_settings_.stampRule();
  const int queue_size = params_.getAtLeast("queue_size", 50000, 1, "messages");
  const double heap_trim_period = params_.getFinite("heap_trim_period", 10.0, "s; <= 0: never");
  const bool autostart = params_.get("autostart", true);
  params_.warnAboutUnknownKeys();

  {
    // Fail early on a bad prior, as the single-axis calibrator does.
    std::lock_guard<std::mutex> lock(mutex_);
    try {
      std::unique_ptr<core::TriadFeed> feed = newFeed();
      if (autostart) feed_ = std::move(feed);
    } catch (const std::exception& e) {
      throw error(e.what());
    }
  }
  serve(queue_size, heap_trim_period, autostart);
}

void TriadCalibratorRos::readSettings() {
  // The calibration settings, as the single-axis calibrator and hrg_bag calibrate read them.
  const YAML::Node tree = privateParameters(pnh_);
  const core::YamlField root(tree, "");
  axis_settings_ = core::CalibrationSettings::parse(root, calibratorNodeOnlyKeys());
  if (axis_settings_.method != core::CalibrationMethodKind::kTriad) {
    throw error("~method is " + core::nameOf(axis_settings_.method) + ": this wrapper runs the triad method only");
  }
  if (root.has("triad")) triad_settings_ = core::TriadCalibrationSettings::parse(root["triad"]);
  params_.claim(core::CalibrationSettings::keyPaths());
  params_.claim(core::CalibrationSettings::formerKeyPaths(), true);  // read when set, never a default
  std::vector<std::string> triad_keys;
  for (const std::string& k : core::TriadCalibrationSettings::keys()) triad_keys.push_back("triad/" + k);
  params_.claim(triad_keys);
  params_.claim({"triad"}, true);  // the core's parser refuses what it does not know in the section

  // Keys of the single-axis methods: accepted in the shared template, not used here (and said so).
  const std::string single_axis_file = params_.get<std::string>("parameter_file", "");
  if (!single_axis_file.empty()) {
    ROS_WARN(
        "%s: ~parameter_file ('%s') is read by the single-axis methods only; the triad reads ~triad_file and "
        "~axis_parameter_files",
        kNode, single_axis_file.c_str());
  }
  params_.get<std::string>("reload_service", "");  // single-axis; the triad calls ~reload_services
  std::vector<std::string> stages;
  params_.getOptional("stages", &stages);
  if (!stages.empty()) throw error("~stages is for the single-axis methods; the triad method runs as one stage");
}

void TriadCalibratorRos::readFiles() {
  // The files: the triad file, then each axis's, by the triad's axis names.
  triad_file_ = params_.get<std::string>("triad_file", "");
  if (triad_file_.empty()) {
    throw error(
        "~triad_file is required: the triad file (axes, frame_id, M, bias; config/triad.yaml is the nominal "
        "one), the prior and the file refreshed");
  }
  core::TriadParameters prior_triad;
  try {
    prior_triad = core::loadTriadFile(triad_file_);
  } catch (const std::exception& e) {
    throw error("~triad_file " + triad_file_ + ": " + e.what());
  }
  axes_ = prior_triad.axes;
  XmlRpc::XmlRpcValue files;
  params_.getOptional("axis_parameter_files", &files);
  const std::string example = "{" + axes_[0] + ": FILE, " + axes_[1] + ": FILE, " + axes_[2] + ": FILE}";
  if (files.getType() != XmlRpc::XmlRpcValue::TypeStruct || files.size() == 0) {
    throw error("~axis_parameter_files is required: a map from each axis of the triad file to its parameter file, " +
                example);
  }
  for (auto it = files.begin(); it != files.end(); ++it) {
    if (std::find(axes_.begin(), axes_.end(), it->first) == axes_.end()) {
      throw error("~axis_parameter_files/" + it->first + ": '" + it->first + "' is not an axis of ~triad_file " +
                  triad_file_ + " (its axes: " + joined(axes_) + ")");
    }
    if (it->second.getType() != XmlRpc::XmlRpcValue::TypeString || std::string(it->second).empty()) {
      throw error("~axis_parameter_files/" + it->first + " must be a file name (a non-empty string)");
    }
  }
  for (int i = 0; i < 3; ++i) {
    if (!files.hasMember(axes_[i])) {
      throw error("~axis_parameter_files/" + axes_[i] + " is missing: each axis's parameter file is needed (its P is " +
                  "kept, and its latitude places the Earth's rate), " + example);
    }
    axis_files_[i] = static_cast<std::string>(files[axes_[i]]);
  }
}

void TriadCalibratorRos::readOutputs() {
  report_file_ = params_.get<std::string>("report_file", "");
  if (report_file_.empty()) report_file_ = core::StagedCalibration::defaultReportPath(triad_file_);
  output_directory_ = params_.get<std::string>("output_directory", "");
  if (output_directory_.empty()) output_directory_ = core::directoryOf(triad_file_);
  write_ = params_.get("write", write_);
  std::vector<std::string> outputs{triad_file_, axis_files_[0], axis_files_[1], axis_files_[2], report_file_};
  const std::vector<std::string> keys{"~triad_file", "~axis_parameter_files/" + axes_[0],
                                      "~axis_parameter_files/" + axes_[1], "~axis_parameter_files/" + axes_[2],
                                      "~report_file"};
  for (std::size_t k = 0; k < outputs.size(); ++k) {
    // Links followed, also a link at the file itself: the writer replaces the file it points to.
    const std::string outside = outsideOutputDirectory(outputs[k], output_directory_);
    if (!outside.empty()) throw error(keys[k] + " " + outside);
  }
  try {
    // Each file is the prior it refreshes, so the outputs are the inputs: they must be distinct (two
    // axes on one file, the report over a parameter file), and no file's .bak another of them.
    const core::TriadResultPaths files{triad_file_, axis_files_};
    core::checkTriadPaths(files, files, {}, {report_file_}, write_);
  } catch (const std::runtime_error& e) {
    throw error(std::string("the files to write must be distinct: ") + e.what());
  }
}

void TriadCalibratorRos::readReloadServices() {
  std::vector<std::string> services{std::string(kAxisPlaceholder) + "/processor/reload", "triad/reload"};
  params_.getOptional("reload_services", &services);
  for (const std::string& s : services) {
    if (s.empty()) continue;
    if (s.find(kAxisPlaceholder) == std::string::npos) {
      reload_services_.push_back(s);
      continue;
    }
    for (const std::string& a : axes_) {
      std::string name = s;
      for (std::size_t at = name.find(kAxisPlaceholder); at != std::string::npos;
           at = name.find(kAxisPlaceholder, at + a.size())) {
        name.replace(at, std::string(kAxisPlaceholder).size(), a);
      }
      reload_services_.push_back(name);
    }
  }
}

void TriadCalibratorRos::serve(int queue_size, double heap_trim_period, bool autostart) {
  result_pub_ = pnh_.advertise<TriadCalibrationResult>("result", 1, true);
  progress_pub_ = pnh_.advertise<std_msgs::Time>("progress", 10);
  ros::NodeHandle in = input_.handle(nh_);
  // The table last: a driver that waits for its turntable listener (driver_sim's
  // wait_for_subscribers) then finds the fixture's and the waves' subscriptions already asked for.
  fixture_sub_ =
      in.subscribe("fixture/position", 100, &TriadCalibratorRos::onFixture, this, ros::TransportHints().tcpNoDelay());
  for (int i = 0; i < 3; ++i) {
    wave_subs_[i] = in.subscribe<WaveState>(
        axes_[i] + "/wave", queue_size, [this, i](const WaveState::ConstPtr& m) { onWave(i, m); }, ros::VoidConstPtr(),
        ros::TransportHints().tcpNoDelay());
  }
  turntable_sub_ = in.subscribe("turntable/state", queue_size, &TriadCalibratorRos::onTurntable, this,
                                ros::TransportHints().tcpNoDelay());
  services_ = CalibratorServices(pnh_, this, &TriadCalibratorRos::onStart, &TriadCalibratorRos::onFinish,
                                 &TriadCalibratorRos::onAbort);
  diagnostics_timer_ = startCalibratorDiagnostics(
      nh_, updater_, "triad calibration", [this](diagnostic_updater::DiagnosticStatusWrapper& s) { diagnose(s); },
      heap_trim_period);
  ROS_INFO("%s: axes %s from %s, %s, %s; triad file %s; %s", kNode, joined(axes_).c_str(), axis_files_[0].c_str(),
           axis_files_[1].c_str(), axis_files_[2].c_str(), triad_file_.c_str(),
           autostart ? "run started" : "waiting for ~start");
  // Threads last: a constructor that throws must not leave a joinable thread behind.
  result_worker_.start([this](Pending& p) { serveResult(p); });
  input_.start();
}

TriadCalibratorRos::~TriadCalibratorRos() {
  // First: the timer runs the diagnostic tasks, some of them members destroyed before it (a
  // FrequencyStatus called after its destruction aborted a test with "pure virtual method called").
  diagnostics_timer_.stop();
  for (ros::Subscriber& s : wave_subs_) s.shutdown();
  turntable_sub_.shutdown();
  fixture_sub_.shutdown();
  input_.stop();
  result_worker_.stop();
}

std::unique_ptr<core::TriadFeed> TriadCalibratorRos::newFeed() const {
  core::TriadParameters prior_triad;
  try {
    prior_triad = core::loadTriadFile(triad_file_);
  } catch (const std::exception& e) {
    throw std::runtime_error("~triad_file " + triad_file_ + ": " + e.what());
  }
  if (prior_triad.axes != axes_) {
    throw std::runtime_error("the triad file's axes changed to " + joined(prior_triad.axes) + " (were " +
                             joined(axes_) + " at start-up): restart the calibrator");
  }
  std::array<core::GyroParameters, 3> priors;
  for (int i = 0; i < 3; ++i) {
    try {
      priors[i] = core::loadParameterFile(axis_files_[i]);
    } catch (const std::exception& e) {
      throw std::runtime_error("~axis_parameter_files/" + axes_[i] + " " + axis_files_[i] + ": " + e.what());
    }
  }
  for (int i = 1; i < 3; ++i) {
    if (!(priors[i].earth_rate == priors[0].earth_rate)) {
      throw std::runtime_error(
          "the axes' parameter files disagree on the Earth's rate (earth_rate: enabled, "
          "latitude): " +
          axes_[0] + " and " + axes_[i] + " sit at one site");
    }
  }
  return std::make_unique<core::TriadFeed>(axis_settings_, triad_settings_, priors, prior_triad, feed_settings_);
}

bool TriadCalibratorRos::startRun(std::string* reason) {
  try {
    feed_ = newFeed();
    restarts_before_ = 0;
    ROS_INFO("%s: run started (priors %s and the axes' files)", kNode, triad_file_.c_str());
    return true;
  } catch (const std::exception& e) {
    *reason = std::string("cannot start the triad run: ") + e.what();
    ROS_ERROR("%s: %s", kNode, reason->c_str());
    feed_.reset();
    return false;
  }
}

void TriadCalibratorRos::maybeFinish() {
  if (feed_->restarts() > restarts_before_) {
    restarts_before_ = feed_->restarts();
    ROS_WARN(
        "%s: a stream went back by more than %.3f s for %d records in a row (bag loop? restarted simulator?): "
        "the run restarted from the priors",
        kNode, feed_settings_.stamps.backward_reset, feed_settings_.stamps.persist);
  }
  if (feed_->shouldFinish()) {
    ROS_INFO("%s: every axis has been along the table axis and the fixture released for %.1f s: finishing", kNode,
             feed_settings_.auto_finish_idle);
    std::string message;
    finishRun(&message);
  }
}

void TriadCalibratorRos::onWave(int axis, const WaveState::ConstPtr& msg) {
  std::lock_guard<std::mutex> lock(mutex_);
  ProgressGuard progress(this, &latest_in_[axis], msg->header.stamp);
  if (!feed_) {
    ++idle_records_;
    return;
  }
  feed_->addWave(axis, toNanoseconds(msg->header.stamp), msg->theta, msg->frequency);
  maybeFinish();
}

void TriadCalibratorRos::onTurntable(const TurntableState::ConstPtr& msg) {
  std::lock_guard<std::mutex> lock(mutex_);
  ProgressGuard progress(this, &latest_in_[3], msg->header.stamp);
  if (!feed_) {
    ++idle_records_;
    return;
  }
  feed_->addTurntable(toNanoseconds(msg->header.stamp), msg->angle, msg->rate, msg->header.seq);
  maybeFinish();
}

void TriadCalibratorRos::onFixture(const FixturePosition::ConstPtr& msg) {
  std::lock_guard<std::mutex> lock(mutex_);
  // The fixture is logged at every change and at least every second: its next record may be 1 s on.
  ProgressGuard progress(this, &latest_in_[4], msg->header.stamp + ros::Duration(1.0));
  if (!feed_) {
    ++idle_records_;
    return;
  }
  const std::uint64_t bad = feed_->counters(core::TriadFeed::kFixture).bad_value;
  feed_->addFixture(fromMessage(*msg));
  if (feed_->counters(core::TriadFeed::kFixture).bad_value > bad) {
    ROS_WARN_THROTTLE(5.0,
                      "%s: fixture position %u '%s' dropped: its body_to_table (%g, %g, %g, %g) is not a "
                      "rotation (norm off 1 by more than 1e-3)",
                      kNode, msg->index, msg->name.c_str(), msg->body_to_table.x, msg->body_to_table.y,
                      msg->body_to_table.z, msg->body_to_table.w);
  }
  maybeFinish();
}

bool TriadCalibratorRos::finishRun(std::string* message) {
  core::TriadOutcome o = feed_->finish();
  const double duration = feed_->duration();
  for (int s = 0; s < core::TriadFeed::kStreamCount; ++s) last_counters_[s] = feed_->counters(s);
  feed_.reset();
  o.triad.calibration.source = "live";
  for (core::CalibrationOutcome& a : o.axes) a.parameters.calibration.source = "live";

  TriadCalibrationResult r = toMessage(o);
  r.header.stamp = ros::Time::now();
  r.triad_file = triad_file_;
  r.axis_parameter_files.assign(axis_files_.begin(), axis_files_.end());
  try {
    core::writeFileAtomically(report_file_, core::emitTriadReport(o));  // whole or not at all
    r.report_file = report_file_;
  } catch (const std::exception& e) {
    ROS_WARN("%s: cannot write the report %s: %s", kNode, report_file_.c_str(), e.what());
  }
  bool written = false;
  if (o.accepted && write_) {
    core::TriadResultPaths paths;
    paths.triad = triad_file_;
    paths.axes = axis_files_;
    const std::string set = axis_files_[0] + ", " + axis_files_[1] + ", " + axis_files_[2] + ", " + triad_file_;
    try {
      r.files_written = core::saveTriadResult(o, paths, true);
      written = true;
      *message = "accepted and written (" + set + ")";
    } catch (const core::BackupNotKept& e) {
      // The new set is in place (the processors are to reload it); a previous version was lost.
      r.files_written = {axis_files_[0], axis_files_[1], axis_files_[2], triad_file_};
      written = true;
      *message = "accepted and written (" + set + "), but: " + e.what();
      r.reason = *message;
    } catch (const std::exception& e) {
      // Nothing replaced: saveTriadResult put back any file already renamed, or names it.
      *message = std::string("accepted but not written: ") + e.what();
      r.reason = *message;
    }
  } else if (o.accepted) {
    *message = "accepted, not written (~write is false)";
    r.reason = *message;
  } else {
    *message = "refused: " + o.reason;  // the message's reason: the outcome's
  }
  r.written = written;
  r.duration = duration;

  ++runs_;
  last_written_ = written;
  last_result_ = *message;
  if (written) {
    ROS_INFO("%s: %s; M from %zu positions, peak nonlinearity of the axes' K %.1f, %.1f, %.1f ppm", kNode,
             message->c_str(), o.positions_fitted, o.axes[0].nonlinearity_ppm, o.axes[1].nonlinearity_ppm,
             o.axes[2].nonlinearity_ppm);
  } else {
    ROS_WARN("%s: %s", kNode, message->c_str());
  }
  for (const core::GateResult& g : o.gates) {
    if (!g.passed) ROS_WARN("%s: gate %s failed: %s", kNode, g.name.c_str(), g.message.c_str());
  }
  for (const std::string& n : o.notes) ROS_INFO("%s: note: %s", kNode, n.c_str());
  result_worker_.push({r, written});
  if (written) ++pending_reloads_;  // ~progress holds until the processors and the triad run the new files
  return written;
}

void TriadCalibratorRos::publishProgress() {
  // Up to where every stream is taken in, at most every 50 ms of stamps; held while written files
  // are being reloaded (for driver_sim's ~pace_topic: the session waits for the slowest stream).
  if (pending_reloads_ > 0) return;
  ros::Time until;
  for (const ros::Time& t : latest_in_) {
    if (t.isZero()) return;
    if (until.isZero() || t < until) until = t;
  }
  if (!last_progress_.isZero() && until >= last_progress_ && until < last_progress_ + ros::Duration(0.05)) return;
  last_progress_ = until;
  std_msgs::Time t;
  t.data = until;
  progress_pub_.publish(t);
}

void TriadCalibratorRos::serveResult(Pending& p) {
  if (p.reload) {
    for (const std::string& s : reload_services_) {
      const std::string service = nh_.resolveName(s);
      std_srvs::Trigger call;
      if (ros::service::waitForService(service, ros::Duration(5.0)) && ros::service::call(service, call) &&
          call.response.success) {
        ROS_INFO("%s: %s: %s", kNode, service.c_str(), call.response.message.c_str());
        p.result.reloaded.push_back(service);
      } else {
        ROS_ERROR("%s: %s %s%s", kNode, service.c_str(),
                  call.response.message.empty() ? "could not be called" : "refused the new files: ",
                  call.response.message.c_str());
        p.result.reload_failed.push_back(service);
      }
      if (result_worker_.stopping()) return;
    }
  }
  result_pub_.publish(p.result);
  if (p.reload) {
    std::lock_guard<std::mutex> lock(mutex_);
    --pending_reloads_;
    publishProgress();  // the driver may be waiting for it with no data left in flight
  }
}

bool TriadCalibratorRos::onStart(StartCalibration::Request& req, StartCalibration::Response& res) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!req.method.empty() && req.method != core::nameOf(core::CalibrationMethodKind::kTriad)) {
    res.success = false;
    res.message = "this calibrator runs the triad method (~method: triad); " + req.method +
                  " calibrates one axis: run a calibrator with ~method " + req.method + " in that axis's namespace";
    return true;
  }
  if (feed_) {
    // Starting over would silently throw away the data gathered so far.
    res.success = false;
    res.message = "a triad run is in progress: ~finish or ~abort it first";
    return true;
  }
  std::string reason;
  res.success = startRun(&reason);
  res.message = res.success ? "started triad" : reason;
  return true;
}

bool TriadCalibratorRos::onFinish(std_srvs::Trigger::Request&, std_srvs::Trigger::Response& res) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!feed_) {
    res.success = false;
    res.message = "no calibration run in progress";
    return true;
  }
  std::string message;
  res.success = finishRun(&message);
  res.message = message;
  return true;
}

bool TriadCalibratorRos::onAbort(std_srvs::Trigger::Request&, std_srvs::Trigger::Response& res) {
  std::lock_guard<std::mutex> lock(mutex_);
  res.success = feed_ != nullptr;
  res.message = feed_ ? "aborted the triad run: nothing written" : "no run in progress";
  if (feed_) {
    for (int s = 0; s < core::TriadFeed::kStreamCount; ++s) last_counters_[s] = feed_->counters(s);
  }
  feed_.reset();
  return true;
}

void TriadCalibratorRos::diagnose(diagnostic_updater::DiagnosticStatusWrapper& stat) {
  std::lock_guard<std::mutex> lock(mutex_);
  auto counters = [this](int s) -> const core::TriadStreamCounters& {
    return feed_ ? feed_->counters(s) : last_counters_[s];
  };
  const char* const stream_names[core::TriadFeed::kStreamCount] = {"fixture", "turntable", "", "", ""};
  std::vector<std::string> names(stream_names, stream_names + core::TriadFeed::kStreamCount);
  for (int i = 0; i < 3; ++i) names[core::TriadFeed::kAxis0 + i] = "axis " + axes_[i];
  if (feed_) {
    const core::TriadStreamCounters& table = counters(core::TriadFeed::kTable);
    std::string silent;
    for (int i = 0; i < 3; ++i) {
      if (counters(core::TriadFeed::kAxis0 + i).received == 0) silent += (silent.empty() ? "" : ", ") + axes_[i];
    }
    const core::TriadStreamCounters& fixture = counters(core::TriadFeed::kFixture);
    const core::FixtureRecord* f = feed_->fixture();
    const std::array<bool, 3>& along = feed_->axesAlongTable();
    std::string covered;
    for (int i = 0; i < 3; ++i) {
      if (along[i]) covered += (covered.empty() ? "" : " ") + axes_[i];
    }
    const std::string position =
        f ? std::to_string(f->index) + " '" + f->name + "' " + (f->locked ? "locked" : "released") : "none yet";
    if (table.received > 100 && !silent.empty()) {
      stat.summary(DiagnosticStatus::WARN, "running; no wave from axis " + silent + " (check <axis>/wave)");
    } else if (table.received > 100 && fixture.received == 0) {
      stat.summary(DiagnosticStatus::WARN, "running; no fixture position (check fixture/position)");
    } else if (fixture.bad_value > 0) {
      stat.summary(DiagnosticStatus::WARN, "running; " + std::to_string(fixture.bad_value) +
                                               " fixture records dropped: orientation not a rotation");
    } else if (feed_->restarts() > 0) {
      stat.summary(DiagnosticStatus::WARN, "running; time went backwards: run restarted");
    } else {
      stat.summary(DiagnosticStatus::OK, "running; fixture position " + position + "; axes along the table so far: " +
                                             (covered.empty() ? std::string("none") : covered));
    }
    stat.add("run", "running");
    stat.add("fixture position", position);
    stat.add("locked positions so far", feed_->lockedPositions());
    stat.add("axes along the table axis so far", covered.empty() ? std::string("none") : covered);
    stat.add("records held for stamp order", feed_->held());
    stat.add("stream time fed (s)", feed_->duration());
    stat.add("restarts (time went backwards)", feed_->restarts());
  } else {
    stat.summary(runs_ > 0 && !last_written_ ? DiagnosticStatus::WARN : DiagnosticStatus::OK,
                 runs_ > 0 ? "idle; last run " + last_result_ : "idle (~start begins a run)");
    stat.add("run", "idle");
    stat.add("records received while idle", idle_records_);
  }
  for (int s = 0; s < core::TriadFeed::kStreamCount; ++s) {
    const core::TriadStreamCounters& c = counters(s);
    const std::string& n = names[s];
    stat.add(n + " received", c.received);
    stat.add(n + " fed", c.fed);
    stat.add(n + " dropped (zero stamp)", c.bad_stamp);
    if (s == core::TriadFeed::kFixture) {
      stat.add(n + " dropped (orientation not a rotation)", c.bad_value);
    } else if (s != core::TriadFeed::kTable) {
      stat.add(n + " dropped (non-finite theta)", c.bad_value);
    }
    stat.add(n + " dropped (out of order)", c.out_of_order);
    stat.add(n + " dropped (stamp jump)", c.stamp_jump);
    stat.add(n + " fed late (behind later stamps)", c.late);
    stat.add(n + " last stamp", stampText(c.last_stamp));
  }
  stat.add("runs", runs_);
  stat.add("triad file", triad_file_);
}

}  // namespace hrg_gyro
