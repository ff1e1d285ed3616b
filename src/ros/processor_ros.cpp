#include "hrg_gyro/ros/processor_ros.h"

#include <cmath>

#include <sensor_msgs/Imu.h>

#include "hrg_gyro/GyroOutput.h"
#include "hrg_gyro/ModelInfo.h"
#include "hrg_gyro/WaveState.h"
#include "hrg_gyro/core/parameter_file.h"
#include "hrg_gyro/ros/conversions.h"
#include "hrg_gyro/ros/diagnostics_timer.h"
#include "hrg_gyro/ros/process_heap.h"

namespace hrg_gyro {
namespace {

using diagnostic_msgs::DiagnosticStatus;

// Variance reported for the axes a single-axis gyro does not measure (REP-145 has no "unknown"
// marker for single axes; a huge variance tells a filter to ignore them).
constexpr double kUnmeasuredVariance = 1e6;

core::ProcessorConfig processorConfig(const ros::NodeHandle& pnh) {
  core::ProcessorConfig c;
  pnh.param("max_gap", c.max_gap, c.max_gap);
  pnh.param("backward_reset", c.backward_reset, c.backward_reset);
  pnh.param("max_rate", c.max_rate, c.max_rate);
  pnh.param("max_consecutive_jumps", c.max_consecutive_jumps, c.max_consecutive_jumps);
  pnh.param("min_anisotropy", c.limits.min_anisotropy, c.limits.min_anisotropy);
  pnh.param("min_amplitude", c.limits.min_amplitude, c.limits.min_amplitude);
  pnh.param("max_amplitude", c.limits.max_amplitude, c.limits.max_amplitude);
  if (!(c.max_gap > 0.0) || !(c.backward_reset > 0.0) || !(c.max_rate > 0.0) || c.max_consecutive_jumps < 0 ||
      !(c.limits.min_anisotropy > 0.0 && c.limits.min_anisotropy < 1.0) ||
      !(c.limits.max_amplitude > c.limits.min_amplitude)) {
    throw std::invalid_argument(
        "processor: invalid limits (~max_gap, ~backward_reset, ~max_rate > 0; ~max_consecutive_jumps >= 0; "
        "0 < ~min_anisotropy < 1; ~max_amplitude > ~min_amplitude)");
  }
  return c;
}

}  // namespace

ProcessorRos::ProcessorRos(ros::NodeHandle nh, ros::NodeHandle pnh)
    : nh_(nh), pnh_(pnh), updater_(nh, pnh, pnh.getNamespace()) {
  if (!pnh_.getParam("parameter_file", parameter_file_) || parameter_file_.empty()) {
    throw std::invalid_argument("processor: ~parameter_file is required");
  }
  auto params = std::make_shared<const core::GyroParameters>(core::loadParameterFile(parameter_file_));
  processor_ = std::make_unique<core::GyroProcessor>(processorConfig(pnh_), params);
  pnh_.param<std::string>("frame_id", frame_id_, "gyro_link");
  pnh_.param("publish_imu", publish_imu_, publish_imu_);
  pnh_.param("angular_velocity_variance", configured_rate_variance_, configured_rate_variance_);
  pnh_.param("stall_timeout", stall_timeout_, stall_timeout_);
  pnh_.param("quadrature_warn", quadrature_warn_, quadrature_warn_);
  pnh_.param("expected_rate", expected_rate_, expected_rate_);
  if (!(expected_rate_ > 0.0)) throw std::invalid_argument("processor: ~expected_rate must be positive (Hz)");
  double tolerance = 0.1;
  pnh_.param("rate_tolerance", tolerance, tolerance);
  min_rate_ = expected_rate_ * (1.0 - tolerance);
  max_rate_ = expected_rate_ * (1.0 + tolerance);
  // 5 s of 10 kHz: a host that deschedules the pipeline for a few seconds delays samples but
  // loses none (a queued message costs a few hundred bytes only while it waits).
  int queue_size = 50000;
  pnh_.param("queue_size", queue_size, queue_size);
  double heap_trim_period = 10.0;  // s of wall time between malloc_trim calls; <= 0: never
  pnh_.param("heap_trim_period", heap_trim_period, heap_trim_period);

  wave_pub_ = nh_.advertise<WaveState>("wave", queue_size);
  output_pub_ = nh_.advertise<GyroOutput>("output", queue_size);
  if (publish_imu_) imu_pub_ = nh_.advertise<sensor_msgs::Imu>("imu/data_raw", queue_size);
  model_pub_ = pnh_.advertise<ModelInfo>("model", 1, true);
  publishModel(ros::Time(0));
  reload_srv_ = pnh_.advertiseService("reload", &ProcessorRos::onReload, this);

  std::string hardware_id;
  pnh_.param<std::string>("hardware_id", hardware_id, "hrg_gyro");
  updater_.setHardwareID(hardware_id);
  frequency_ = std::make_unique<diagnostic_updater::FrequencyStatus>(
      diagnostic_updater::FrequencyStatusParam(&min_rate_, &max_rate_, 0.0, 5), "channels rate");
  double max_delay = 1.0;
  pnh_.param("max_stamp_delay", max_delay, max_delay);
  stamps_ = std::make_unique<diagnostic_updater::TimeStampStatus>(
      diagnostic_updater::TimeStampStatusParam(-max_delay, max_delay), "channels stamps");
  updater_.add(*frequency_);
  updater_.add(*stamps_);
  updater_.add("input", this, &ProcessorRos::diagnoseInput);
  updater_.add("wave", this, &ProcessorRos::diagnoseWave);
  updater_.add("model", this, &ProcessorRos::diagnoseModel);
  addProcessHeapDiagnostic(updater_, heap_trim_period);
  channels_sub_ = input_.handle(nh_).subscribe("channels", queue_size, &ProcessorRos::onChannels, this,
                                               ros::TransportHints().tcpNoDelay());
  input_.start();
  diagnostics_timer_ = createDiagnosticsTimer(nh_, updater_);
  ROS_INFO("processor: %s (K0 %.6f, %zu K harmonics, calibration %s)", parameter_file_.c_str(),
           params->scale_factor.meanAt(NAN), params->scale_factor.orders().size(), params->calibration.method.c_str());
}

ProcessorRos::~ProcessorRos() {
  channels_sub_.shutdown();
  input_.stop();
}

void ProcessorRos::publishModel(const ros::Time& since) {
  const core::GyroParameters& p = processor_->parameters();
  ModelInfo m;
  m.header.stamp = since;
  m.header.frame_id = frame_id_;
  m.parameter_file = parameter_file_;
  m.calibration_method = p.calibration.method;
  m.calibration_time = p.calibration.time;
  m.k0 = p.scale_factor.meanAt(NAN);
  m.k_harmonics = static_cast<std::uint32_t>(p.scale_factor.orders().size());
  m.d_harmonics = static_cast<std::uint32_t>(p.drift.orders().size());
  m.frequency_dependent = p.scale_factor.frequencyDependent() || p.drift.frequencyDependent();
  model_pub_.publish(m);
}

double ProcessorRos::angularVelocityVariance() const {
  if (configured_rate_variance_ >= 0.0) return configured_rate_variance_;
  // White angle noise sigma^2 per sample gives second differences of variance 6 sigma^2 and a
  // per-sample rate (difference / dt) of variance 2 sigma^2 / dt^2.
  return dt_last_ > 0.0 ? (d2_variance_ / 3.0) / (dt_last_ * dt_last_) : kUnmeasuredVariance;
}

void ProcessorRos::onChannels(const ChannelAmplitudes::ConstPtr& msg) {
  std::lock_guard<std::mutex> lock(mutex_);
  frequency_->tick();
  stamps_->tick(msg->header.stamp);
  if (seen_input_ && msg->header.seq > last_seq_ + 1) dropped_ += msg->header.seq - last_seq_ - 1;
  last_seq_ = msg->header.seq;
  seen_input_ = true;
  last_input_ = ros::Time::now();
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

  auto wave = boost::make_shared<WaveState>(toWaveMessage(*msg, r.wave, frame_id_));
  wave_pub_.publish(wave);
  if (!r.has_output) return;
  last_flags_ = r.flags;

  const core::AngleIncrement& inc = r.increment;
  auto out = boost::make_shared<GyroOutput>(toOutputMessage(wave->header, r));
  output_pub_.publish(out);

  const bool continuous = !(r.flags & (core::kFlagGap | core::kFlagReset));
  if (continuous) {
    if (history_ >= 2) {
      const double d2 = r.alpha - 2.0 * alpha1_ + alpha2_;
      d2_variance_ += (d2 * d2 - d2_variance_) * (history_ < 1000 ? 1.0 / (history_ - 1) : 1e-3);
    }
    alpha2_ = alpha1_;
    alpha1_ = r.alpha;
    if (history_ < 1000) ++history_;
    dt_last_ = inc.dt;
  } else {
    history_ = 0;
  }
  if (!publish_imu_ || !continuous) return;
  auto imu = boost::make_shared<sensor_msgs::Imu>();
  imu->header = wave->header;
  // REP-145: no orientation and no acceleration from this sensor.
  imu->orientation_covariance[0] = -1.0;
  imu->linear_acceleration_covariance[0] = -1.0;
  imu->angular_velocity.z = out->rate;
  imu->angular_velocity_covariance[0] = kUnmeasuredVariance;
  imu->angular_velocity_covariance[4] = kUnmeasuredVariance;
  imu->angular_velocity_covariance[8] = angularVelocityVariance();
  imu_pub_.publish(imu);
}

bool ProcessorRos::onReload(std_srvs::Trigger::Request&, std_srvs::Trigger::Response& res) {
  std::shared_ptr<const core::GyroParameters> params;
  try {
    params = std::make_shared<const core::GyroParameters>(core::loadParameterFile(parameter_file_));
  } catch (const std::exception& e) {
    std::lock_guard<std::mutex> lock(mutex_);
    ++failed_reloads_;
    last_reload_error_ = e.what();
    res.success = false;
    res.message = std::string("kept the previous model: ") + e.what();
    ROS_ERROR("processor: reload refused: %s", e.what());
    return true;
  }
  std::lock_guard<std::mutex> lock(mutex_);
  processor_->setParameters(params);
  publishModel(last_stamp_);
  ++reloads_;
  last_reload_error_.clear();
  res.success = true;
  char buf[256];
  std::snprintf(buf, sizeof buf, "loaded %s: K0 %.9f, %zu K harmonics, %zu D harmonics, calibration %s %s",
                parameter_file_.c_str(), params->scale_factor.meanAt(NAN), params->scale_factor.orders().size(),
                params->drift.orders().size(), params->calibration.method.c_str(), params->calibration.time.c_str());
  res.message = buf;
  ROS_INFO("processor: %s", buf);
  return true;
}

void ProcessorRos::diagnoseInput(diagnostic_updater::DiagnosticStatusWrapper& stat) {
  std::lock_guard<std::mutex> lock(mutex_);
  const core::ProcessorCounters& c = processor_->counters();
  const double since = seen_input_ ? (ros::Time::now() - last_input_).toSec() : INFINITY;
  if (!seen_input_) {
    stat.summary(DiagnosticStatus::ERROR, "no channel amplitudes received yet");
  } else if (since > stall_timeout_) {
    stat.summaryf(DiagnosticStatus::ERROR, "input stalled: no channel amplitudes for %.2f s", since);
  } else if (c.zero_stamp + c.duplicate + c.out_of_order > reported_.zero_stamp + reported_.duplicate + reported_.out_of_order) {
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
                            (c.amplitude_out_of_range - reported_.amplitude_out_of_range) +
                            (c.jumps - reported_.jumps);
  const double ratio = has_wave_ && last_wave_.amplitude > 0.0 ? std::abs(last_wave_.quadrature) / last_wave_.amplitude : 0.0;
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
  if (!last_reload_error_.empty()) {
    stat.summary(DiagnosticStatus::WARN, "last reload refused, previous model kept: " + last_reload_error_);
  } else if (last_flags_ & core::kFlagFrequencyUnknown) {
    stat.summary(DiagnosticStatus::WARN, "frequency-dependent model but the input carries no frequency");
  } else if (last_flags_ & core::kFlagFrequencyOutOfRange) {
    stat.summary(DiagnosticStatus::WARN, "resonator frequency outside the model's nodes: end values held");
  } else {
    stat.summary(DiagnosticStatus::OK, "model loaded");
  }
  stat.add("parameter file", parameter_file_);
  stat.add("calibration method", p.calibration.method);
  stat.add("calibration time", p.calibration.time);
  stat.add("K0", p.scale_factor.meanAt(NAN));
  stat.add("K harmonics", p.scale_factor.orders().size());
  stat.add("D0 (rad/s)", p.drift.meanAt(NAN));
  stat.add("frequency dependent", p.scale_factor.frequencyDependent() || p.drift.frequencyDependent());
  stat.add("reloads", reloads_);
  stat.add("refused reloads", failed_reloads_);
}

}  // namespace hrg_gyro
