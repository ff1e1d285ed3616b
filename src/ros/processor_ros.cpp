#include "hrg_gyro/ros/processor_ros.h"

#include <sensor_msgs/Imu.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>

#include "hrg_gyro/GyroOutput.h"
#include "hrg_gyro/ModelInfo.h"
#include "hrg_gyro/WaveState.h"
#include "hrg_gyro/core/calibration/calibration_outcome.h"
#include "hrg_gyro/core/model/parameter_file.h"
#include "hrg_gyro/ros/conversions.h"
#include "hrg_gyro/ros/diagnostics_timer.h"
#include "hrg_gyro/ros/process_heap.h"

namespace hrg_gyro {
namespace {

using diagnostic_msgs::DiagnosticStatus;

// Variance reported for the axes a single-axis gyro does not measure (REP-145 has no "unknown"
// marker for single axes; a huge variance tells a filter to ignore them).
constexpr double kUnmeasuredVariance = 1e6;

/// Runs `check`, a core validation: a ConfigError becomes the node's start-up error naming its parameter.
template <class Check>
void checkAsParameters(const Check& check) {
  try {
    check();  // the same rules as hrg_bag process
  } catch (const core::ConfigError& e) {
    throw std::invalid_argument("processor: ~" + e.key() + ": " + e.problem());
  }
}

core::ProcessorConfig processorConfig(ParameterReader& params) {
  core::ProcessorConfig c;
  c.max_gap = params.get("max_gap", c.max_gap);
  c.backward_reset = params.get("backward_reset", c.backward_reset);
  c.jump_persist = params.get("jump_persist", c.jump_persist);
  c.max_rate = params.get("max_rate", c.max_rate);
  c.max_consecutive_jumps = params.get("max_consecutive_jumps", c.max_consecutive_jumps);
  c.limits.min_anisotropy = params.get("min_anisotropy", c.limits.min_anisotropy);
  c.limits.min_amplitude = params.get("min_amplitude", c.limits.min_amplitude);
  c.limits.max_amplitude = params.get("max_amplitude", c.limits.max_amplitude);
  checkAsParameters([&] { core::validate(c); });
  return c;
}

core::PrecessionWatchSettings precessionWatchSettings(ParameterReader& params, const core::ProcessorConfig& config) {
  core::PrecessionWatchSettings w;
  w.hold = params.get("precession_hold", w.hold);
  w.backward_reset = config.backward_reset;  // the stamps' rule, as for the channels
  checkAsParameters([&] { w.validate(); });
  return w;
}

core::BiasCaptureSettings biasCaptureSettings(ParameterReader& params) {
  core::BiasCaptureSettings b;
  b.duration = params.get("bias_capture/duration", b.duration);
  b.block = params.get("bias_capture/block", b.block);
  b.max_motion = params.get("bias_capture/max_motion", b.max_motion);
  b.max_bias = params.get("bias_capture/max_bias", b.max_bias);
  b.validate();
  return b;
}

}  // namespace

ProcessorRos::ProcessorRos(ros::NodeHandle nh, ros::NodeHandle pnh)
    : nh_(nh), pnh_(pnh), params_(pnh, "processor"), updater_(nh, pnh, pnh.getNamespace()) {
  parameter_file_ = params_.get<std::string>("parameter_file", "");
  if (parameter_file_.empty()) throw std::invalid_argument("processor: ~parameter_file is required (the gyro model)");
  auto params = std::make_shared<const core::GyroParameters>(core::loadParameterFile(parameter_file_));
  processor_ = std::make_unique<core::GyroProcessor>(processorConfig(params_), params);
  precession_ = core::PrecessionWatch(precessionWatchSettings(params_, processor_->config()));
  frame_id_ = params_.get<std::string>("frame_id", "gyro_link");
  publish_imu_ = params_.get("publish_imu", publish_imu_);
  core::RateNoiseSettings noise;
  noise.configured_variance = params_.get("angular_velocity_variance", noise.configured_variance);
  noise.initial_variance = params_.get("initial_angular_velocity_variance", noise.initial_variance);
  try {
    rate_noise_ = core::RateNoiseEstimator(noise);
  } catch (const core::ConfigError& e) {
    throw std::invalid_argument("processor: ~" + e.key() + " " + e.problem());
  }
  stall_timeout_ = params_.get("stall_timeout", stall_timeout_);
  shutdown_when_idle_ = params_.get("shutdown_when_idle", shutdown_when_idle_);
  if (!std::isfinite(shutdown_when_idle_) || shutdown_when_idle_ < 0.0) {
    throw std::invalid_argument("processor: ~shutdown_when_idle must be 0 (never) or positive (s)");
  }
  quadrature_warn_ = params_.get("quadrature_warn", quadrature_warn_);
  expected_rate_ = params_.get("expected_rate", expected_rate_);
  if (!(expected_rate_ > 0.0)) throw std::invalid_argument("processor: ~expected_rate must be positive (Hz)");
  const double tolerance = params_.get("rate_tolerance", 0.1);
  min_rate_ = expected_rate_ * (1.0 - tolerance);
  max_rate_ = expected_rate_ * (1.0 + tolerance);
  // 5 s of 10 kHz: a host that deschedules the pipeline for a few seconds delays samples but
  // loses none (a queued message costs a few hundred bytes only while it waits).
  const int queue_size = params_.get("queue_size", 50000);
  // s of wall time between malloc_trim calls; <= 0: never
  const double heap_trim_period = params_.get("heap_trim_period", 10.0);
  bias_settings_ = biasCaptureSettings(params_);
  bias_capture_save_ = params_.get("bias_capture/save", bias_capture_save_);
  bias_capture_timeout_ = params_.get("bias_capture/timeout", 3.0 * bias_settings_.duration + 5.0);
  const std::string hardware_id = params_.get<std::string>("hardware_id", "hrg_gyro");
  const double max_delay = params_.get("max_stamp_delay", 1.0);
  params_.claim({"diagnostic_period"});  // read by diagnostic_updater itself

  wave_pub_ = nh_.advertise<WaveState>("wave", queue_size);
  output_pub_ = nh_.advertise<GyroOutput>("output", queue_size);
  if (publish_imu_) imu_pub_ = nh_.advertise<sensor_msgs::Imu>("imu/data_raw", queue_size);
  model_pub_ = pnh_.advertise<ModelInfo>("model", 1, true);
  publishModel(ros::Time(0));
  reload_srv_ = pnh_.advertiseService("reload", &ProcessorRos::onReload, this);
  capture_srv_ = pnh_.advertiseService("capture_bias", &ProcessorRos::onCaptureBias, this);

  updater_.setHardwareID(hardware_id);
  frequency_ = std::make_unique<diagnostic_updater::FrequencyStatus>(
      diagnostic_updater::FrequencyStatusParam(&min_rate_, &max_rate_, 0.0, 5), "channels rate");
  stamps_ = std::make_unique<diagnostic_updater::TimeStampStatus>(
      diagnostic_updater::TimeStampStatusParam(-max_delay, max_delay), "channels stamps");
  updater_.add(*frequency_);
  updater_.add(*stamps_);
  updater_.add("input", this, &ProcessorRos::diagnoseInput);
  updater_.add("wave", this, &ProcessorRos::diagnoseWave);
  updater_.add("model", this, &ProcessorRos::diagnoseModel);
  updater_.add("precession", this, &ProcessorRos::diagnosePrecession);
  addProcessHeapDiagnostic(updater_, heap_trim_period);
  // Listen to the channels only once the outputs have their listeners: a driver that waits for this
  // node's subscription then waits for the whole chain (a calibrator that connected to wave late
  // lost the first seconds of a session at 40x sim time on a loaded host).
  wait_wave_ = params_.get("wait_for_subscribers/wave", 0);
  wait_output_ = params_.get("wait_for_subscribers/output", 0);
  wait_timeout_ = params_.get("wait_timeout", 0.0);
  params_.warnAboutUnknownKeys();
  queue_size_ = queue_size;
  input_.start();
  diagnostics_timer_ = createDiagnosticsTimer(nh_, updater_);
  if (outputsListened()) {
    subscribeChannels();
  } else {
    wait_start_ = ros::WallTime::now();
    wait_timer_ = nh_.createWallTimer(ros::WallDuration(0.01), &ProcessorRos::onWaitTimer, this);
  }
  ROS_INFO("processor: %s (K0 %.6f, %zu K harmonics, calibration %s)", parameter_file_.c_str(),
           params->scale_factor.meanAt(NAN), params->scale_factor.orders().size(),
           params->calibration.method.name().c_str());
}

ProcessorRos::~ProcessorRos() {
  // First: the timer runs the diagnostic tasks, some of them members destroyed before it (a
  // FrequencyStatus called after its destruction aborted a test with "pure virtual method called").
  diagnostics_timer_.stop();
  wait_timer_.stop();
  channels_sub_.shutdown();
  precession_sub_.shutdown();
  input_.stop();
}

bool ProcessorRos::outputsListened() const {
  return static_cast<int>(wave_pub_.getNumSubscribers()) >= wait_wave_ &&
         static_cast<int>(output_pub_.getNumSubscribers()) >= wait_output_;
}

void ProcessorRos::subscribeChannels() {
  channels_sub_ = input_.handle(nh_).subscribe("channels", queue_size_, &ProcessorRos::onChannels, this,
                                               ros::TransportHints().tcpNoDelay());
  // On the same thread as the channels: the two are handled in the order they arrive.
  precession_sub_ = input_.handle(nh_).subscribe("precession/state", queue_size_, &ProcessorRos::onPrecession, this,
                                                 ros::TransportHints().tcpNoDelay());
  listening_ = true;
}

void ProcessorRos::onWaitTimer(const ros::WallTimerEvent&) {
  if (listening_) return;
  const double waited = (ros::WallTime::now() - wait_start_).toSec();
  if (outputsListened()) {
    wait_timer_.stop();
    subscribeChannels();
    ROS_INFO("processor: listening to channels after %.1f s (wave %u/%d, output %u/%d subscribers)", waited,
             wave_pub_.getNumSubscribers(), wait_wave_, output_pub_.getNumSubscribers(), wait_output_);
  } else if (wait_timeout_ > 0.0 && waited > wait_timeout_) {
    wait_timer_.stop();
    subscribeChannels();
    ROS_WARN(
        "processor: listening to channels after %.1f s without all expected subscribers (wave %u/%d, output %u/%d)",
        waited, wave_pub_.getNumSubscribers(), wait_wave_, output_pub_.getNumSubscribers(), wait_output_);
  } else if (waited >= next_wait_note_) {
    next_wait_note_ = waited + 10.0;
    ROS_WARN(
        "processor: still waiting after %.0f s for subscribers (wave %u/%d, output %u/%d) before listening to "
        "channels",
        waited, wave_pub_.getNumSubscribers(), wait_wave_, output_pub_.getNumSubscribers(), wait_output_);
  }
}

void ProcessorRos::publishModel(const ros::Time& since) {
  const core::GyroParameters& p = processor_->parameters();
  ModelInfo m;
  m.header.stamp = since;
  m.header.frame_id = frame_id_;
  m.parameter_file = parameter_file_;
  m.calibration_method = p.calibration.method.name();
  m.calibration_time = p.calibration.time;
  m.k0 = p.scale_factor.meanAt(NAN);
  m.k_harmonics = static_cast<std::uint32_t>(p.scale_factor.orders().size());
  m.d_harmonics = static_cast<std::uint32_t>(p.drift.orders().size());
  m.frequency_dependent = p.scale_factor.frequencyDependent() || p.drift.frequencyDependent();
  model_pub_.publish(m);
}

void ProcessorRos::onChannels(const ChannelAmplitudes::ConstPtr& msg) {
  std::lock_guard<std::mutex> lock(mutex_);
  frequency_->tick();
  stamps_->tick(msg->header.stamp);
  if (seen_input_ && msg->header.seq > last_seq_ + 1) dropped_ += msg->header.seq - last_seq_ - 1;
  last_seq_ = msg->header.seq;
  seen_input_ = true;
  last_input_ = ros::Time::now();
  last_input_wall_ = ros::WallTime::now();
  last_stamp_ = msg->header.stamp;

  const core::ChannelSample in = fromMessage(*msg);
  const core::ProcessorResult r = processor_->process(in);
  if (r.verdict == core::SampleVerdict::kRejectedStamp || r.verdict == core::SampleVerdict::kDuplicate ||
      r.verdict == core::SampleVerdict::kOutOfOrder) {
    ROS_WARN_THROTTLE(5.0, "processor: dropped a sample with a bad stamp (%s)",
                      r.verdict == core::SampleVerdict::kRejectedStamp ? "zero"
                      : r.verdict == core::SampleVerdict::kDuplicate   ? "duplicate"
                                                                       : "out of order");
  } else if (r.verdict == core::SampleVerdict::kRejectedValue) {
    ROS_WARN_THROTTLE(5.0, "processor: rejected a sample: %s", core::toString(r.wave_status));
  } else if (r.verdict == core::SampleVerdict::kRejectedJump) {
    ROS_WARN_THROTTLE(5.0, "processor: rejected a wave-angle jump above ~max_rate (glitch or sign flip)");
  } else if (r.verdict == core::SampleVerdict::kStampJump) {
    ROS_WARN_THROTTLE(5.0,
                      "processor: dropped a sample whose stamp jumped (back by more than ~backward_reset or ahead by "
                      "more than ~max_gap); a jump is taken only after ~jump_persist samples in a row");
  }
  if (r.flags & core::kFlagReset) {
    ROS_WARN("processor: time went backwards (bag loop?): state reset, alpha restarts");
    frequency_->clear();  // its window of past ticks is in the future now
  }
  if (r.flags & core::kFlagGap) {
    ROS_WARN_THROTTLE(5.0, "processor: %.3f s gap in the input: not integrated across", r.increment.dt);
  }
  if (!r.has_wave) return;
  last_wave_ = r.wave;
  has_wave_ = true;
  // An output covers (the previous accepted stamp, this one]; a first sample only starts the next.
  const core::Nanoseconds from = previous_accepted_;
  previous_accepted_ = in.stamp;

  auto wave = boost::make_shared<WaveState>(toWaveMessage(*msg, r.wave, frame_id_));
  wave_pub_.publish(wave);
  if (!r.has_output) return;
  last_flags_ = r.flags;
  precession_.addOutput(from, in.stamp);
  pending_.push_back({boost::make_shared<GyroOutput>(toOutputMessage(wave->header, r)), r.increment});
  releaseOutputs();
}

void ProcessorRos::onPrecession(const PrecessionState::ConstPtr& msg) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (precession_.addState({toNanoseconds(msg->header.stamp), msg->rate, msg->angle})) {
    last_precession_ = *msg;
  } else {
    ROS_WARN_THROTTLE(5.0, "processor: dropped a precession state (non-finite, zero, duplicate or out-of-order stamp)");
  }
  releaseOutputs();
}

void ProcessorRos::releaseOutputs() {
  core::PrecessionDecision d;
  while (precession_.next(&d)) {
    const PendingOutput p = std::move(pending_.front());
    pending_.pop_front();
    GyroOutput& out = *p.output;
    if (d.flagged()) out.flags |= core::kFlagPrecessing;
    if (d.flagged() != precessing_) {
      precessing_ = d.flagged();
      const char* by =
          last_precession_.source.empty() ? "a node the driver does not name" : last_precession_.source.c_str();
      if (d.verdict == core::PrecessionVerdict::kUnknown) {
        ROS_WARN(
            "processor: the precession state stopped short of the output (more than ~precession_hold behind): "
            "outputs flagged PRECESSING from %.3f s, the wave may be turning",
            out.header.stamp.toSec());
      } else if (precessing_) {
        ROS_WARN(
            "processor: the wave is being turned on command (%g rad/s, commanded by %s): outputs flagged "
            "PRECESSING from %.3f s; they are not the body's rate",
            d.rate, by, out.header.stamp.toSec());
      } else {
        ROS_INFO("processor: the wave is no longer turned on command: outputs unflagged from %.3f s",
                 out.header.stamp.toSec());
      }
    }
    output_pub_.publish(p.output);

    if (capture_ && !capture_->finished() && capture_->add(p.increment, out.flags)) capture_cv_.notify_all();

    rate_noise_.add(out.alpha, out.dt, out.flags);
    const bool continuous = !(out.flags & (core::kFlagGap | core::kFlagReset));
    if (!publish_imu_ || !continuous) continue;
    auto imu = boost::make_shared<sensor_msgs::Imu>();
    imu->header = out.header;
    // REP-145: no orientation and no acceleration from this sensor.
    imu->orientation_covariance[0] = -1.0;
    imu->linear_acceleration_covariance[0] = -1.0;
    imu->angular_velocity.z = out.rate;
    imu->angular_velocity_covariance[0] = kUnmeasuredVariance;
    imu->angular_velocity_covariance[4] = kUnmeasuredVariance;
    // A precessed sample's rate is the wave's, not the body's: REP-145 has no flag, so it is marked
    // as not measured, as x and y are (a filter that weighs by covariance ignores it).
    imu->angular_velocity_covariance[8] =
        (out.flags & core::kFlagPrecessing) ? kUnmeasuredVariance : rate_noise_.variance();
    imu_pub_.publish(imu);
  }
}

bool ProcessorRos::onReload(std_srvs::Trigger::Request&, std_srvs::Trigger::Response& res) {
  std::shared_ptr<const core::GyroParameters> params;
  try {
    params = std::make_shared<const core::GyroParameters>(core::loadParameterFile(parameter_file_));
  } catch (const std::exception& e) {
    std::lock_guard<std::mutex> lock(mutex_);
    reload_.refuse(e.what(), &res);
    return true;
  }
  std::lock_guard<std::mutex> lock(mutex_);
  if (capture_ && !capture_->finished()) {
    capture_->abort("the model was reloaded during the capture");
    capture_cv_.notify_all();
  }
  processor_->setParameters(params);
  publishModel(last_stamp_);
  reload_.loaded();
  res.success = true;
  char buf[256];
  std::snprintf(buf, sizeof buf, "loaded %s: K0 %.9f, %zu K harmonics, %zu D harmonics, calibration %s %s",
                parameter_file_.c_str(), params->scale_factor.meanAt(NAN), params->scale_factor.orders().size(),
                params->drift.orders().size(), params->calibration.method.name().c_str(),
                params->calibration.time.c_str());
  res.message = buf;
  ROS_INFO("processor: %s", buf);
  return true;
}

bool ProcessorRos::onCaptureBias(std_srvs::Trigger::Request&, std_srvs::Trigger::Response& res) {
  std::unique_lock<std::mutex> lock(mutex_);
  if (capture_) {
    res.success = false;
    res.message = "a bias capture is already running";
    return true;
  }
  capture_ = std::make_unique<core::BiasCapture>(bias_settings_, processor_->parameters());
  ROS_INFO("processor: capturing the turn-on bias over %.1f s: keep the gyro still", bias_settings_.duration);
  // Samples arrive on the input thread; this waits (the lock released) until the capture ends.
  const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(bias_capture_timeout_);
  while (!capture_->finished()) {
    capture_cv_.wait_for(lock, std::chrono::milliseconds(100));
    if (!ros::ok()) {
      capture_->abort("shutting down");
    } else if (!capture_->finished() && ros::WallTime::now() > deadline) {
      char why[160];
      std::snprintf(why, sizeof why, "too few outputs: %.2f of %.1f s of input within %.1f s (~bias_capture/timeout)",
                    capture_->result().seconds, bias_settings_.duration, bias_capture_timeout_);
      capture_->abort(why);
    }
  }
  const core::BiasCaptureResult result = capture_->result();
  capture_.reset();
  if (!result.accepted) {
    res.success = false;
    res.message = "bias capture refused, model unchanged: " + result.reason;
    ROS_WARN("processor: %s", res.message.c_str());
    return true;
  }
  auto params = std::make_shared<core::GyroParameters>(result.parameters);
  const std::string when = core::utcNow();
  params->calibration.notes = core::notesAfterBiasCapture(params->calibration.notes, when);
  std::string saved = " (in memory only: ~bias_capture/save is false)";
  if (bias_capture_save_) {
    try {
      core::saveParameterFile(parameter_file_, *params);
      saved = "; written to " + parameter_file_ + " (previous file kept as .bak)";
    } catch (const std::exception& e) {
      res.success = false;
      res.message =
          "bias captured but the parameter file could not be written, model unchanged: " + std::string(e.what());
      ROS_ERROR("processor: %s", res.message.c_str());
      return true;
    }
  }
  processor_->setParameters(params);
  publishModel(last_stamp_);
  ++bias_captures_;
  last_bias_capture_ = when + ": " + result.reason;
  res.success = true;
  res.message = result.reason + saved;
  ROS_INFO("processor: bias capture: %s", res.message.c_str());
  return true;
}

bool ProcessorRos::idleFor(double seconds) {
  std::lock_guard<std::mutex> lock(mutex_);
  return seen_input_ && (ros::WallTime::now() - last_input_wall_).toSec() > seconds;
}

void ProcessorRos::diagnoseInput(diagnostic_updater::DiagnosticStatusWrapper& stat) {
  std::lock_guard<std::mutex> lock(mutex_);
  const core::ProcessorCounters& c = processor_->counters();
  // The longer of ROS and wall time: under sim time a stopped /clock stops the first.
  const double since = seen_input_ ? std::max((ros::Time::now() - last_input_).toSec(),
                                              (ros::WallTime::now() - last_input_wall_).toSec())
                                   : INFINITY;
  const std::uint64_t lost = dropped_ - dropped_reported_;
  dropped_reported_ = dropped_;
  if (!seen_input_ && !listening_) {
    stat.summaryf(DiagnosticStatus::WARN,
                  "waiting for subscribers (wave %u/%d, output %u/%d) before listening to channels",
                  wave_pub_.getNumSubscribers(), wait_wave_, output_pub_.getNumSubscribers(), wait_output_);
  } else if (!seen_input_) {
    stat.summary(DiagnosticStatus::ERROR, "no channel amplitudes received yet");
  } else if (since > stall_timeout_) {
    stat.summaryf(DiagnosticStatus::ERROR, "input stalled: no channel amplitudes for %.2f s", since);
  } else if (lost > 0) {
    stat.summaryf(DiagnosticStatus::WARN, "%lu messages lost (sequence gaps) since the last report",
                  static_cast<unsigned long>(lost));
  } else if (c.stamp_jumps > reported_.stamp_jumps) {
    stat.summary(DiagnosticStatus::WARN, "samples whose stamp jumped (a glitch) dropped");
  } else if (c.zero_stamp + c.duplicate + c.out_of_order >
             reported_.zero_stamp + reported_.duplicate + reported_.out_of_order) {
    stat.summary(DiagnosticStatus::WARN, "samples with zero, duplicate or out-of-order stamps dropped");
  } else if (c.gaps > reported_.gaps || c.resets > reported_.resets) {
    stat.summary(DiagnosticStatus::WARN, c.resets > reported_.resets ? "time went backwards: state reset"
                                                                     : "gap in the input: not integrated across");
  } else {
    stat.summary(DiagnosticStatus::OK, "receiving");
  }
  stat.add("received", c.received);
  stat.add("seconds since last sample", since);
  stat.add("lost (sequence gaps)", dropped_);
  stat.add("zero stamps", c.zero_stamp);
  stat.add("duplicate stamps", c.duplicate);
  stat.add("out-of-order stamps", c.out_of_order);
  stat.add("stamp jumps dropped", c.stamp_jumps);
  stat.add("gaps not integrated", c.gaps);
  stat.add("largest gap (s)", c.largest_gap);
  stat.add("resets (time went backwards)", c.resets);
}

void ProcessorRos::diagnoseWave(diagnostic_updater::DiagnosticStatusWrapper& stat) {
  std::lock_guard<std::mutex> lock(mutex_);
  const core::ProcessorCounters& c = processor_->counters();
  const std::uint64_t received = c.received - reported_.received;
  const std::uint64_t bad = (c.non_finite - reported_.non_finite) + (c.no_signal - reported_.no_signal) +
                            (c.degenerate - reported_.degenerate) +
                            (c.amplitude_out_of_range - reported_.amplitude_out_of_range) + (c.jumps - reported_.jumps);
  const double ratio =
      has_wave_ && last_wave_.amplitude > 0.0 ? std::abs(last_wave_.quadrature) / last_wave_.amplitude : 0.0;
  if (received > 0 && bad == received) {
    std::string why = c.non_finite > reported_.non_finite   ? "non-finite channel amplitudes"
                      : c.degenerate > reported_.degenerate ? "degenerate wave (A close to B)"
                      : c.no_signal > reported_.no_signal   ? "no signal"
                      : c.jumps > reported_.jumps           ? "wave-angle jumps"
                                                            : "amplitude out of range";
    stat.summaryf(DiagnosticStatus::ERROR, "every sample rejected: %s", why.c_str());
  } else if (bad > 0) {
    stat.summaryf(DiagnosticStatus::WARN, "%lu of %lu samples rejected", static_cast<unsigned long>(bad),
                  static_cast<unsigned long>(received));
  } else if (ratio > quadrature_warn_) {
    stat.summaryf(DiagnosticStatus::WARN, "quadrature B/A = %.3f above %.3f", ratio, quadrature_warn_);
  } else if (!has_wave_) {
    stat.summary(DiagnosticStatus::WARN, "no wave state yet");
  } else {
    stat.summary(DiagnosticStatus::OK, "standing wave healthy");
  }
  stat.add("amplitude A", last_wave_.amplitude);
  stat.add("quadrature B", last_wave_.quadrature);
  stat.add("B/A", ratio);
  stat.add("phase (rad)", last_wave_.phase);
  stat.add("theta (rad)", last_wave_.theta);
  stat.add("rejected non-finite", c.non_finite);
  stat.add("rejected no signal", c.no_signal);
  stat.add("rejected degenerate", c.degenerate);
  stat.add("rejected amplitude range", c.amplitude_out_of_range);
  stat.add("rejected jumps", c.jumps);
  stat.add("outputs", c.outputs);
  reported_ = c;
}

void ProcessorRos::diagnoseModel(diagnostic_updater::DiagnosticStatusWrapper& stat) {
  std::lock_guard<std::mutex> lock(mutex_);
  const core::GyroParameters& p = processor_->parameters();
  if (reload_.lastRefused()) {
    stat.summary(DiagnosticStatus::WARN, reload_.refusalSummary());
  } else if (last_flags_ & core::kFlagFrequencyUnknown) {
    stat.summary(DiagnosticStatus::WARN, "frequency-dependent model but the input carries no frequency");
  } else if (last_flags_ & core::kFlagFrequencyOutOfRange) {
    stat.summary(DiagnosticStatus::WARN, "resonator frequency outside the model's nodes: end values held");
  } else if (p.calibration.method.isNone()) {
    // A model nobody calibrated carries the nominal scale factor: its output is off by up to percents.
    stat.summary(DiagnosticStatus::WARN, "uncalibrated model (calibration method: none): nominal K and D");
  } else {
    stat.summary(DiagnosticStatus::OK, "model loaded");
  }
  stat.add("parameter file", parameter_file_);
  stat.add("calibration method", p.calibration.method.name());
  stat.add("calibration time", p.calibration.time);
  stat.add("K0", p.scale_factor.meanAt(NAN));
  stat.add("K harmonics", p.scale_factor.orders().size());
  stat.add("D0 (rad/s)", p.drift.meanAt(NAN));
  stat.add("frequency dependent", p.scale_factor.frequencyDependent() || p.drift.frequencyDependent());
  reload_.addCounts(stat);
  stat.add("bias captures", bias_captures_);
  stat.add("last bias capture", last_bias_capture_);
}

void ProcessorRos::diagnosePrecession(diagnostic_updater::DiagnosticStatusWrapper& stat) {
  std::lock_guard<std::mutex> lock(mutex_);
  const core::PrecessionWatchCounters& c = precession_.counters();
  const std::uint64_t precessing = c.precessing - reported_precession_.precessing;
  const std::uint64_t unknown = c.unknown - reported_precession_.unknown;
  const std::uint64_t dropped = c.dropped_states - reported_precession_.dropped_states;
  const PrecessionState& s = last_precession_;
  const std::string by = s.commands == 0    ? "nobody (no command executed)"
                         : s.source.empty() ? "a node the driver does not name"
                                            : s.source;
  if (!precession_.seenState()) {
    stat.summary(DiagnosticStatus::OK, "no precession state received: a gyro without a precession loop");
  } else if (unknown > 0) {
    stat.summaryf(DiagnosticStatus::WARN,
                  "precession state stopped short of the outputs: %lu outputs flagged PRECESSING (the wave may be "
                  "turning)",
                  static_cast<unsigned long>(unknown));
  } else if (precessing > 0 || s.rate != 0.0) {
    stat.summaryf(DiagnosticStatus::WARN,
                  "wave turned on command: %lu outputs flagged PRECESSING since the last report; %g rad/s in force, "
                  "commanded by %s",
                  static_cast<unsigned long>(precessing), s.rate, by.c_str());
  } else if (dropped > 0) {
    stat.summaryf(DiagnosticStatus::WARN, "%lu precession states dropped (non-finite, zero or out-of-order stamps)",
                  static_cast<unsigned long>(dropped));
  } else {
    stat.summary(DiagnosticStatus::OK, "wave not turned on command (0 rad/s in force)");
  }
  stat.add("commanded rate (rad/s)", s.rate);
  stat.add("commanded by", by);
  stat.add("commands executed", s.commands);
  stat.add("state stamp", s.header.stamp.toSec());
  stat.add("outputs flagged precessing", c.precessing);
  stat.add("outputs flagged (state unknown)", c.unknown);
  stat.add("outputs waiting for the precession state", precession_.waiting());
  stat.add("precession states", c.states);
  stat.add("precession states dropped", c.dropped_states);
  stat.add("precession timelines", c.timelines);
  reported_precession_ = c;
}

}  // namespace hrg_gyro
