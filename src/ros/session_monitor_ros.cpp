#include "hrg_gyro/ros/session_monitor_ros.h"

#include <std_msgs/String.h>
#include <yaml-cpp/yaml.h>

#include <cstdint>
#include <fstream>
#include <optional>
#include <sstream>

#include "hrg_gyro/core/common/atomic_file.h"
#include "hrg_gyro/core/evaluation/session_summary.h"
#include "hrg_gyro/core/model/calibration_method_kind.h"
#include "hrg_gyro/core/model/parameter_file.h"
#include "hrg_gyro/core/simulation/injected_model.h"
#include "hrg_gyro/ros/conversions.h"
#include "hrg_gyro/ros/param_tree.h"

namespace hrg_gyro {
namespace {

/// A summary file appears whole or not at all (scripts wait for it to exist).
void writeSummary(const std::string& path, const std::string& text) {
  try {
    core::writeFileAtomically(path, text);
  } catch (const std::exception& e) {
    ROS_ERROR("session_monitor: cannot write %s: %s", path.c_str(), e.what());
  }
}

/// Largest |estimated - injected| / standard error over the calibration's first K and D terms.
double worstZ(const core::SessionSummary& s) {
  double worst_z = 0.0;
  auto zs = [&](const core::HarmonicFitResult& e, const core::HarmonicFitResult& i) {
    worst_z = std::max(worst_z, std::abs(e.mean - i.mean) / e.mean_std);
    for (std::size_t j = 0; j < e.orders.size(); ++j) {
      worst_z = std::max(worst_z, std::abs(e.cos[j] - i.cos[j]) / e.cos_std[j]);
      worst_z = std::max(worst_z, std::abs(e.sin[j] - i.sin[j]) / e.sin_std[j]);
    }
  };
  zs(s.calibration.scale_factor[0], s.injected.scale_factor);
  zs(s.calibration.drift[0], s.injected.drift);
  return worst_z;
}

}  // namespace

SessionMonitorRos::SessionMonitorRos(ros::NodeHandle nh, ros::NodeHandle pnh)
    : nh_(nh), pnh_(pnh), params_(pnh, "session_monitor") {
  prefix_ = params_.get<std::string>("verification_prefix", "verify");
  summary_file_ = params_.get<std::string>("summary_file", "");
  prior_file_ = params_.get<std::string>("prior_parameter_file", "");
  shutdown_when_done_ = params_.get("shutdown_when_done", shutdown_when_done_);
  const std::string scenario_ns = params_.get<std::string>("scenario_namespace", "driver_sim");
  params_.warnAboutUnknownKeys();
  scenario_ = std::make_unique<core::SimulationConfig>(
      core::SimulationConfig::parse(core::YamlField(privateParameters(ros::NodeHandle(nh_, scenario_ns)), scenario_ns),
                                    core::nodeOnlyScenarioKeys()));
  after_ = std::make_unique<Track>(evaluation_);
  before_ = std::make_unique<Track>(evaluation_);
  const int q = 20000;
  const auto hints = ros::TransportHints().tcpNoDelay();
  truth_sub_ = nh_.subscribe("truth", q, &SessionMonitorRos::onTruth, this, hints);
  Track* after = after_.get();
  Track* before = before_.get();
  output_sub_ = nh_.subscribe<GyroOutput>(
      "output", q, [this, after](const GyroOutput::ConstPtr& m) { onOutput(m, after); }, ros::VoidConstPtr(), hints);
  before_sub_ = nh_.subscribe<GyroOutput>(
      "before/output", q, [this, before](const GyroOutput::ConstPtr& m) { onOutput(m, before); }, ros::VoidConstPtr(),
      hints);
  result_sub_ = nh_.subscribe("calibrator/result", 1, &SessionMonitorRos::onResult, this);
  done_sub_ = nh_.subscribe("driver_sim/done", 1, &SessionMonitorRos::onDone, this);
  model_sub_ = nh_.subscribe("processor/model", 10, &SessionMonitorRos::onModel, this);
  summary_pub_ = pnh_.advertise<std_msgs::String>("summary", 1, true);
  done_pub_ = pnh_.advertise<std_msgs::Bool>("done", 1, true);
}

void SessionMonitorRos::onTruth(const GroundTruth::ConstPtr& msg) {
  std::lock_guard<std::mutex> lock(mutex_);
  last_input_wall_ = ros::WallTime::now();
  const core::Nanoseconds t = toNanoseconds(msg->header.stamp);
  if (!truth_.empty() && t <= truth_.back().stamp) return;  // out of order: cannot be paired reliably
  const bool verify = msg->segment.rfind(prefix_, 0) == 0;
  if (verify && first_verification_stamp_ == 0) first_verification_stamp_ = t;
  if (verify) {
    ++verification_truths_;
    last_verification_stamp_ = t;
  }
  truth_.push_back({t, msg->table_rate, msg->inertial_angle, msg->inertial_rate, verify});
  match(after_.get());
  match(before_.get());
  // Drop truth every active track has passed (a track that never sent output does not hold it back).
  core::Nanoseconds passed = INT64_MAX;
  for (const Track* tr : {after_.get(), before_.get()}) {
    if (tr->passed != 0) passed = std::min(passed, tr->passed);
  }
  while (!truth_.empty() && (truth_.front().stamp < passed || truth_.size() > 200000)) truth_.pop_front();
}

void SessionMonitorRos::onOutput(const GyroOutput::ConstPtr& msg, Track* track) {
  std::lock_guard<std::mutex> lock(mutex_);
  last_input_wall_ = ros::WallTime::now();
  if (msg->flags & (GyroOutput::FLAG_GAP | GyroOutput::FLAG_RESET)) return;
  track->pending.push_back({toNanoseconds(msg->header.stamp), msg->theta_mid, msg->alpha});
  match(track);
}

void SessionMonitorRos::match(Track* track) {
  // Both streams are in stamp order: look each pending output up by binary search.
  while (!track->pending.empty() && !truth_.empty()) {
    const OutputSample& o = track->pending.front();
    if (o.stamp > truth_.back().stamp) break;  // its truth has not arrived yet
    const auto it = std::lower_bound(truth_.begin(), truth_.end(), o.stamp,
                                     [](const TruthSample& a, core::Nanoseconds t) { return a.stamp < t; });
    if (it != truth_.end() && it->stamp == o.stamp) {
      if (it->verify) {
        track->evaluator.add(o.stamp, o.theta_mid, o.alpha, it->table_rate, it->inertial_angle, it->inertial_rate);
        ++track->samples;
      }
    } else if (first_verification_stamp_ != 0 && o.stamp >= first_verification_stamp_) {
      ++track->unmatched;
    }
    track->passed = o.stamp;
    track->pending.pop_front();
  }
  while (track->pending.size() > 200000) track->pending.pop_front();
}

void SessionMonitorRos::onResult(const CalibrationResult::ConstPtr& msg) {
  std::lock_guard<std::mutex> lock(mutex_);
  const std::optional<core::CalibrationMethodKind> method = core::findCalibrationMethod(msg->method);
  if (!method) {
    ROS_WARN("session_monitor: ignoring a calibration result of unknown method '%s'", msg->method.c_str());
    return;
  }
  if (!core::traitsOf(*method).estimates_k_and_d && result_) return;  // keep the K/D stage for the summary
  result_ = msg;
}

void SessionMonitorRos::onModel(const ModelInfo::ConstPtr& msg) {
  std::lock_guard<std::mutex> lock(mutex_);
  // The calibrated K and D apply from here (not a nominal model, nor P alone before its K/D stage).
  const std::optional<core::CalibrationMethodKind> method = core::findCalibrationMethod(msg->calibration_method);
  if (method && core::traitsOf(*method).estimates_k_and_d) {
    model_since_ = toNanoseconds(msg->header.stamp);
  }
}

void SessionMonitorRos::onDone(const std_msgs::Bool::ConstPtr& msg) {
  if (!msg->data || finish_timer_.isValid()) return;
  // Let in-flight outputs arrive first, however late the pipeline runs: finish once every active
  // track has an output for every verification truth, or once nothing came for kQuietAfterDone s
  // (under sim time the clock has stopped: wall time). A fixed 1 s wait lost the last outputs of a
  // processor run late on a busy host.
  finish_timer_ = nh_.createWallTimer(ros::WallDuration(0.1), [this](const ros::WallTimerEvent&) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (finished_) return;
    bool complete = verification_truths_ > 0;
    for (const Track* tr : {after_.get(), before_.get()}) {
      if (tr->passed != 0 && (tr->samples < verification_truths_ || !tr->pending.empty())) complete = false;
    }
    if (complete || (ros::WallTime::now() - last_input_wall_).toSec() > kQuietAfterDone) {
      finish_timer_.stop();
      finish();
    }
  });
}

void SessionMonitorRos::finish() {
  if (finished_) return;
  finished_ = true;
  core::SessionSummary s;
  s.before = before_->evaluator.result();
  s.after = after_->evaluator.result();
  std::vector<int> k_orders{2, 4, 6, 8}, d_orders{2, 4};
  if (result_) {
    s.calibration = fromMessage(*result_);
    if (!result_->scale_factor.empty())
      k_orders.assign(result_->scale_factor[0].orders.begin(), result_->scale_factor[0].orders.end());
    if (!result_->drift.empty()) d_orders.assign(result_->drift[0].orders.begin(), result_->drift[0].orders.end());
  } else {
    s.has_calibration = false;
    s.calibration.reason = "no calibration result received";
  }
  core::CorrectionMatrix p;
  if (!prior_file_.empty()) p = core::loadParameterFile(prior_file_).correction;
  if (result_ && s.has_calibration && core::traitsOf(s.calibration.method).estimates_k_and_d) {
    for (int i = 0; i < 4; ++i) p.p[i] = result_->correction[i];  // the P the K/D stage measured through
  }
  s.injected = core::computeEffectiveModel(*scenario_, p, k_orders, d_orders);

  // The calibrated model must apply from before the first verification sample.
  const bool in_force = model_since_ >= 0 && first_verification_stamp_ != 0 && model_since_ < first_verification_stamp_;
  if (!in_force) {
    s.warnings.push_back(model_since_ < 0 ? "the processor never loaded a calibrated model"
                                          : "the calibrated model took effect only after the verification began");
  }
  if (after_->samples < verification_truths_ || before_->samples < verification_truths_) {
    s.warnings.push_back("outputs missing for some verification samples (after " + std::to_string(after_->samples) +
                         ", before " + std::to_string(before_->samples) + " of " +
                         std::to_string(verification_truths_) + ")");
  }
  std::ostringstream text;
  core::printSessionSummary(text, s);
  if (!summary_file_.empty()) writeSummary(summary_file_, text.str());
  ROS_INFO_STREAM("session_monitor:" << text.str());

  YAML::Emitter y;
  y << YAML::BeginMap;
  y << YAML::Key << "calibration_accepted" << YAML::Value << (result_ && result_->accepted);
  y << YAML::Key << "calibration_written" << YAML::Value << (result_ && result_->written);
  y << YAML::Key << "model_in_force" << YAML::Value << in_force;
  y << YAML::Key << "before_ppm" << YAML::Value << s.before.nonlinearity_ppm;
  y << YAML::Key << "after_ppm" << YAML::Value << s.after.nonlinearity_ppm;
  y << YAML::Key << "after_sigma_ppm" << YAML::Value << s.after.nonlinearity_sigma_ppm;
  y << YAML::Key << "evaluation_ok" << YAML::Value << (s.before.ok && s.after.ok);
  y << YAML::Key << "after_samples" << YAML::Value << after_->samples;
  y << YAML::Key << "before_samples" << YAML::Value << before_->samples;
  y << YAML::Key << "verification_samples" << YAML::Value << verification_truths_;
  y << YAML::Key << "after_unmatched" << YAML::Value << after_->unmatched;
  y << YAML::Key << "before_unmatched" << YAML::Value << before_->unmatched;
  y << YAML::Key << "angle_error_before" << YAML::Value << s.before.angle_error_max;
  y << YAML::Key << "angle_error_after" << YAML::Value << s.after.angle_error_max;
  const double worst_z = result_ && !s.calibration.scale_factor.empty() ? worstZ(s) : 0.0;
  y << YAML::Key << "worst_z" << YAML::Value << worst_z;
  y << YAML::EndMap;
  if (!summary_file_.empty()) writeSummary(summary_file_ + ".yaml", std::string(y.c_str()) + "\n");
  std_msgs::String summary;
  summary.data = y.c_str();
  summary_pub_.publish(summary);
  std_msgs::Bool done;
  done.data = true;
  done_pub_.publish(done);
  // Loaded as a nodelet this ends the whole manager: meant for demos and tests, where the session
  // is over (a nodelet cannot end a launch any other way).
  if (shutdown_when_done_) ros::requestShutdown();
}

}  // namespace hrg_gyro
