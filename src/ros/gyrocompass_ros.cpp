#include "hrg_gyro/ros/gyrocompass_ros.h"

#include <cmath>
#include <cstdio>

#include "hrg_gyro/AlignmentResult.h"
#include "hrg_gyro/core/common/number_format.h"
#include "hrg_gyro/core/common/yaml_field.h"
#include "hrg_gyro/core/model/triad_file.h"
#include "hrg_gyro/ros/conversions.h"
#include "hrg_gyro/ros/diagnostics_timer.h"
#include "hrg_gyro/ros/param_tree.h"

namespace hrg_gyro {
namespace {

using diagnostic_msgs::DiagnosticStatus;

std::invalid_argument startupError(const std::string& what) { return std::invalid_argument("gyrocompass: " + what); }

std::string format(const char* fmt, double a, double b) {
  char buf[128];
  std::snprintf(buf, sizeof buf, fmt, a, b);
  return buf;
}

}  // namespace

GyrocompassRos::GyrocompassRos(ros::NodeHandle nh, ros::NodeHandle pnh)
    : nh_(nh),
      pnh_(pnh),
      params_(pnh, "gyrocompass"),
      updater_(nh, params_.checkDiagnosticPeriod(), pnh.getNamespace()) {
  // The alignment's settings, by the parser `hrg_bag align --settings` uses.
  try {
    settings_ = core::AlignmentSettings::parse(core::YamlField(privateParameters(pnh_), ""),
                                               core::AlignmentSettings::nodeKeys());
  } catch (const core::ConfigError& e) {
    throw startupError(std::string("~") + e.what());
  }
  params_.claim(core::AlignmentSettings::keyPaths());
  const std::string triad_file = params_.get<std::string>("triad_file", "");
  if (!triad_file.empty()) {
    try {
      triad_ = core::loadTriadFile(triad_file);
    } catch (const core::ConfigError& e) {
      throw startupError(std::string("~triad_file: ") + e.what());
    }
    have_triad_file_ = true;
  }
  if (settings_.mode == core::AlignmentMode::kSweep && !have_triad_file_) {
    throw startupError("~mode sweep needs ~triad_file (the axes' names, M and the body bias)");
  }
  // No noise model, no start: every term given, from an Allan file, or the residual bias from a
  // calibrated triad file (the probe resolves them as every alignment will).
  try {
    settings_ = core::Gyrocompass(settings_, triad_).settings();
  } catch (const core::ConfigError& e) {
    throw startupError(std::string("~") + e.what());
  }
  hold_enabled_ = params_.get("hold/enabled", hold_enabled_);
  hold_settings_.latitude = settings_.latitude;
  hold_settings_.noise = settings_.noise;
  hold_settings_.covariance_interval =
      params_.getPositive("hold/covariance_interval", hold_settings_.covariance_interval, "s");
  hold_settings_.max_bridge = params_.getInRange("hold/max_bridge", hold_settings_.max_bridge, 0.0, 1.0, "s");
  hold_settings_.scale_factor_sigma = params_.get<double>("hold/scale_factor_sigma", hold_settings_.scale_factor_sigma);
  stall_timeout_ = params_.getPositive("stall_timeout", stall_timeout_, "s");
  const bool align_at_startup = params_.get("align_at_startup", false);
  const int queue_size = params_.getAtLeast("queue_size", 50000, 1, "messages");
  const std::vector<std::string> unknown = params_.unknownKeys();
  if (!unknown.empty()) throw startupError("~" + unknown.front() + ": unknown parameter (see config/gyrocompass.yaml)");
  if (hold_enabled_) {
    try {
      hold_settings_.validate();
    } catch (const core::ConfigError& e) {
      throw startupError("~" + std::string(e.what()));
    }
  }

  result_pub_ = nh_.advertise<AlignmentResult>("alignment/result", 1, true);
  alignment_imu_pub_ = nh_.advertise<sensor_msgs::Imu>("alignment/imu", 1, true);
  if (hold_enabled_) imu_pub_ = nh_.advertise<sensor_msgs::Imu>("imu/data", queue_size);
  align_srv_ = pnh_.advertiseService("align", &GyrocompassRos::onAlign, this);

  updater_.setHardwareID("hrg_gyro_gyrocompass");
  updater_.add("gyrocompass", this, &GyrocompassRos::diagnoseAlignment);
  if (hold_enabled_) updater_.add("attitude hold", this, &GyrocompassRos::diagnoseHold);

  subscribe(queue_size);
  diagnostics_timer_ = createDiagnosticsTimer(nh_, updater_);
  ROS_INFO(
      "gyrocompass: mode %s%s, gyros %s, latitude %.6f rad, window %.1f s, level %s, estimator %s; noise: %s; "
      "~align starts one",
      toString(settings_.mode), settings_.single_gyro ? " (one gyro)" : "", gyro_topic_.c_str(), settings_.latitude,
      settings_.duration,
      settings_.level.source == core::LevelSource::kDeclared ? "declared"
      : imu_accelerometer_                                   ? "imu/data_raw's linear_acceleration"
                                                             : "accel/data_raw",
      toString(settings_.estimator), settings_.noise_sources.summary().c_str());
  if (align_at_startup) {
    std::lock_guard<std::mutex> lock(mutex_);
    const std::string refused = start(0.0, "");
    if (!refused.empty()) ROS_ERROR("gyrocompass: the alignment at start-up was refused: %s", refused.c_str());
  }
}

void GyrocompassRos::subscribe(int queue_size) {
  // What the configured mode needs; the gyro stream (triad/output or imu/data_raw) also for the hold.
  const ros::TransportHints hints = ros::TransportHints().tcpNoDelay();
  const bool imu_input = settings_.gyro_input == core::GyroInput::kImu;
  if (imu_input) {
    imu_ = std::make_unique<core::ImuIncrementConverter>(settings_.imu.converter);
    imu_accelerometer_ = settings_.level.source == core::LevelSource::kAccelerometer && settings_.imu.accelerometer;
    subscribers_.push_back(nh_.subscribe("imu/data_raw", queue_size, &GyrocompassRos::onImu, this, hints));
  } else {
    subscribers_.push_back(nh_.subscribe("triad/output", queue_size, &GyrocompassRos::onTriad, this, hints));
  }
  gyro_topic_ = nh_.resolveName(imu_input ? "imu/data_raw" : "triad/output");
  if (settings_.single_gyro) {
    subscribers_.push_back(nh_.subscribe("output", queue_size, &GyrocompassRos::onGyro, this, hints));
  }
  if (settings_.mode == core::AlignmentMode::kIndexed) {
    subscribers_.push_back(nh_.subscribe("turntable/state", queue_size, &GyrocompassRos::onIndexer, this, hints));
  }
  if (settings_.level.source == core::LevelSource::kAccelerometer && !imu_accelerometer_) {
    subscribers_.push_back(nh_.subscribe("accel/data_raw", queue_size, &GyrocompassRos::onAccelerometer, this, hints));
  }
  if (have_triad_file_) {
    for (std::size_t a = 0; a < 3; ++a) {
      const std::string& axis = triad_.axes[a];
      subscribers_.push_back(nh_.subscribe<GyroOutput>(
          triadAxisTopic(axis, "output"), queue_size, [this, a](const GyroOutput::ConstPtr& m) { onSweepAxis(a, m); },
          ros::VoidConstPtr(), hints));
      subscribers_.push_back(nh_.subscribe<PrecessionState>(
          triadAxisTopic(axis, "precession/state"), queue_size,
          [this, a](const PrecessionState::ConstPtr& m) { onPrecession(a, m); }, ros::VoidConstPtr(), hints));
    }
  }
}

GyrocompassRos::~GyrocompassRos() {
  // First: the timer runs the diagnostic tasks, which read the members below.
  diagnostics_timer_.stop();
  for (ros::Subscriber& s : subscribers_) s.shutdown();
}

std::string GyrocompassRos::start(double duration, const std::string& mode) {
  if (running_ && !alignmentStalled()) {
    const core::AlignmentProgress p = running_->progress();
    return format("an alignment runs (%.1f of %.1f s): wait for its result", p.seconds, p.duration);
  }
  if (!std::isfinite(duration) || duration < 0.0) return "duration must be 0 (the configured) or positive, s";
  core::AlignmentSettings s = settings_;
  if (duration > 0.0) s.duration = duration;
  try {
    if (!mode.empty()) s.mode = core::parseAlignmentMode(mode);
    s.validate();
  } catch (const core::ConfigError& e) {
    return e.what();
  }
  if (s.mode == core::AlignmentMode::kSweep && !have_triad_file_) {
    return "mode sweep needs ~triad_file (its axes' topics are not subscribed)";
  }
  if (s.mode == core::AlignmentMode::kIndexed && settings_.mode != core::AlignmentMode::kIndexed) {
    return "mode indexed needs ~mode indexed at start-up (turntable/state is not subscribed)";
  }
  if (running_) {
    const core::AlignmentProgress p = running_->progress();
    ROS_WARN("gyrocompass: the stalled alignment (%.1f of %.1f s, no %s for %.1f s) replaced by a new one", p.seconds,
             p.duration, running_topic_.c_str(), quietFor(alignment_input_));
  }
  running_ = std::make_unique<core::Gyrocompass>(s, triad_);
  running_frame_.clear();
  running_topic_ = s.single_gyro ? nh_.resolveName("output")
                   : s.mode == core::AlignmentMode::kSweep
                       ? nh_.resolveName(triadAxisTopic(triad_.axes[0], "output")) + " (or another axis's)"
                       : gyro_topic_;
  alignment_input_ = ros::WallTime::now();
  ++alignments_;
  ROS_INFO("gyrocompass: alignment %llu started: mode %s, %.1f s of gyro stamps",
           static_cast<unsigned long long>(alignments_), toString(s.mode), s.duration);
  finishIfComplete();  // a latitude beyond max_latitude refuses it at once
  if (!running_ && last_ && !last_->accepted) return "refused (" + last_->gate + "): " + last_->reason;
  return "";
}

void GyrocompassRos::finishIfComplete() {
  if (!running_ || !running_->complete()) return;
  core::AlignmentResult r = running_->finish();
  const bool triad = !r.single_gyro;
  running_.reset();
  const std::string frame = running_frame_;
  result_pub_.publish(toMessage(r, frame));
  if (r.accepted) {
    alignment_imu_pub_.publish(toAlignmentImuMessage(r, frame));
    ROS_INFO("gyrocompass: %s", r.summary().c_str());
    if (hold_enabled_ && triad) {
      hold_ = std::make_unique<core::AttitudeHold>(hold_settings_, core::holdStartFrom(r));
      hold_frame_ = frame;
      hold_input_ = ros::WallTime::now();
    }
  } else {
    ROS_ERROR("gyrocompass: alignment refused (%s): %s", r.gate.c_str(), r.reason.c_str());
  }
  last_ = std::move(r);
}

void GyrocompassRos::onTriad(const TriadOutput::ConstPtr& msg) {
  std::lock_guard<std::mutex> lock(mutex_);
  takeBodySample(fromMessage(*msg), msg->header.frame_id);
}

void GyrocompassRos::onImu(const sensor_msgs::Imu::ConstPtr& msg) {
  std::lock_guard<std::mutex> lock(mutex_);
  const core::ImuSample in = fromImuMessage(*msg);
  if (imu_accelerometer_ && running_) {
    if (const auto force = imu_->specificForce(in)) running_->addAccelerometer({in.stamp, *force});
  }
  const std::optional<core::TriadBodySample> sample = imu_->convert(in);
  if (sample)
    takeBodySample(*sample, settings_.imu.body_frame.empty() ? msg->header.frame_id : settings_.imu.body_frame);
}

void GyrocompassRos::takeBodySample(const core::TriadBodySample& sample, const std::string& frame) {
  if (hold_ && hold_->holding()) {
    hold_input_ = ros::WallTime::now();
    if (hold_->add(sample)) {
      imu_pub_.publish(toHeldImuMessage(*hold_, sample, hold_frame_));
    } else if (!hold_->holding()) {
      ROS_WARN("gyrocompass: attitude hold lost: %s; align again", hold_->lostReason().c_str());
    }
  }
  if (!running_ || running_->settings().single_gyro || running_->settings().mode == core::AlignmentMode::kSweep) {
    return;
  }
  running_frame_ = frame;
  const std::uint64_t before = running_->progress().samples;
  running_->addTriad(sample);
  noteProgress(before);
  finishIfComplete();
}

void GyrocompassRos::onGyro(const GyroOutput::ConstPtr& msg) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!running_ || !running_->settings().single_gyro) return;
  running_frame_ = msg->header.frame_id;
  const std::uint64_t before = running_->progress().samples;
  running_->addAxis(toAxisOutput(*msg));
  noteProgress(before);
  finishIfComplete();
}

void GyrocompassRos::onSweepAxis(std::size_t axis, const GyroOutput::ConstPtr& msg) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!running_ || running_->settings().mode != core::AlignmentMode::kSweep) return;
  running_frame_ = triad_.frame_id;
  const std::uint64_t before = running_->progress().samples;
  running_->addSweepAxis(axis, toAxisOutput(*msg));
  noteProgress(before);
  finishIfComplete();
}

void GyrocompassRos::noteProgress(std::uint64_t samples_before) {
  // A sample taken, or the window full: the input moves. Dropped ones (a stamp that cannot fill the
  // window) leave the stall timer running, so a window that cannot fill says so.
  if (running_ && (running_->progress().samples != samples_before || running_->complete())) {
    alignment_input_ = ros::WallTime::now();
  }
}

void GyrocompassRos::onPrecession(std::size_t axis, const PrecessionState::ConstPtr& msg) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (running_ && running_->settings().mode == core::AlignmentMode::kSweep)
    running_->addPrecession(axis, fromMessage(*msg));
}

void GyrocompassRos::onIndexer(const TurntableState::ConstPtr& msg) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (running_) running_->addIndexer(fromMessage(*msg));
}

void GyrocompassRos::onAccelerometer(const sensor_msgs::Imu::ConstPtr& msg) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (running_) running_->addAccelerometer(fromAccelerometerMessage(*msg));
}

bool GyrocompassRos::onAlign(StartAlignment::Request& req, StartAlignment::Response& res) {
  std::lock_guard<std::mutex> lock(mutex_);
  const std::string refused = start(req.duration, req.mode);
  res.success = refused.empty();
  res.message = refused.empty() ? "aligning: " + core::formatDouble(running_->settings().duration) +
                                      " s of gyro stamps, mode " + toString(running_->settings().mode)
                                : refused;
  if (!refused.empty()) ROS_WARN("gyrocompass: ~align refused: %s", refused.c_str());
  return true;
}

void GyrocompassRos::diagnoseAlignment(diagnostic_updater::DiagnosticStatusWrapper& stat) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (running_) {
    const core::AlignmentProgress p = running_->progress();
    const double quiet = quietFor(alignment_input_);
    if (quiet > stall_timeout_) {
      stat.summaryf(DiagnosticStatus::ERROR,
                    "aligning, input stalled: no %s sample taken for %.1f s (%.1f of %.1f s; %llu dropped); ~align "
                    "restarts it",
                    running_topic_.c_str(), quiet, p.seconds, p.duration, static_cast<unsigned long long>(p.dropped));
    } else {
      stat.summaryf(DiagnosticStatus::WARN, "aligning: %.1f of %.1f s (%s)", p.seconds, p.duration,
                    toString(running_->settings().mode));
    }
    stat.add("seconds without gyro input", quiet);
    stat.add("window seconds", p.seconds);
    stat.add("window duration", p.duration);
    stat.add("samples", p.samples);
    stat.add("gaps", p.gaps);
    stat.add("dropped records", p.dropped);
    stat.add("window restarts", p.restarts);
    stat.add("indexer records", p.indexer);
    stat.add("accelerometer records", p.accelerometer);
    if (imu_) {
      stat.add("imu samples converted", imu_->counts().samples);
      stat.add("imu gaps", imu_->counts().gaps);
      stat.add("imu samples dropped", imu_->counts().dropped);
      stat.add("imu typical period s", imu_->typicalPeriod());
    }
  } else if (!last_) {
    stat.summary(DiagnosticStatus::WARN, "no alignment yet: call ~align");
  } else if (last_->accepted) {
    stat.summaryf(DiagnosticStatus::OK, "heading %.4f +- %.4f deg (true, clockwise from North; %s, %.1f s)",
                  last_->heading, last_->heading_sigma, toString(last_->mode), last_->seconds);
  } else {
    stat.summaryf(DiagnosticStatus::ERROR, "alignment refused (%s): %s", last_->gate.c_str(), last_->reason.c_str());
  }
  stat.add("alignments started", alignments_);
  stat.add("noise sources", settings_.noise_sources.summary());
  if (!last_) return;
  const core::AlignmentResult& r = *last_;
  stat.add("last accepted", r.accepted ? "true" : "false");
  stat.add("last gate", r.gate);
  stat.add("last heading deg", r.heading);
  stat.add("last heading sigma deg", r.heading_sigma);
  stat.add("last roll rad", r.attitude.roll);
  stat.add("last pitch rad", r.attitude.pitch);
  stat.add("budget noise rad", r.budget.noise);
  stat.add("budget residual bias rad", r.budget.residual_bias);
  stat.add("budget drift harmonics rad", r.budget.drift_harmonics);
  stat.add("budget bias random walk rad", r.budget.bias_random_walk);
  stat.add("budget level rad", r.budget.level);
  stat.add("budget indexer rad", r.budget.indexer);
  stat.add("budget total rad", r.budget.total);
  stat.add("horizontal earth rate rad/s", r.horizontal_rate);
  stat.add("expected horizontal earth rate rad/s", r.budget.horizontal_earth_rate);
  stat.add("scatter", r.scatter);
  stat.add("last estimator", r.estimator);
  stat.add("last estimator reason", r.estimator_reason);
  stat.add("low frequency scatter", r.low_frequency_scatter);
  stat.add("base steps carried", r.base_steps.size());
  stat.add("excluded s", r.excluded_seconds);
  for (const core::EarthCheck& c : r.earth_checks) {
    stat.add("earth check " + c.name, core::formatDouble(c.measured) + " (expected " + core::formatDouble(c.expected) +
                                          ", sigma " + core::formatDouble(c.sigma) + (c.passed ? ")" : ", FAILED)"));
  }
}

void GyrocompassRos::diagnoseHold(diagnostic_updater::DiagnosticStatusWrapper& stat) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!hold_) {
    stat.summary(DiagnosticStatus::WARN, "not holding: no accepted alignment of the triad yet");
    return;
  }
  const double quiet = quietFor(hold_input_);
  if (hold_->holding() && quiet > stall_timeout_) {
    stat.summaryf(DiagnosticStatus::ERROR, "holding, input stalled: no %s for %.1f s; the attitude is not updated",
                  gyro_topic_.c_str(), quiet);
  } else if (hold_->holding()) {
    stat.summaryf(DiagnosticStatus::OK, "holding %.1f s: heading %.4f +- %.4f deg", hold_->elapsed(), hold_->heading(),
                  hold_->headingSigma());
  } else {
    stat.summaryf(DiagnosticStatus::ERROR, "attitude lost after %.1f s: %s; align again", hold_->elapsed(),
                  hold_->lostReason().c_str());
  }
  stat.add(imu_ ? "seconds without imu input" : "seconds without triad input", quiet);
  stat.add("elapsed s", hold_->elapsed());
  stat.add("heading deg", hold_->heading());
  stat.add("heading sigma deg", hold_->headingSigma());
  stat.add("dropped samples", hold_->dropped());
  stat.add("bridged samples", hold_->bridged());
  stat.add("lost reason", hold_->lostReason());
}

}  // namespace hrg_gyro
