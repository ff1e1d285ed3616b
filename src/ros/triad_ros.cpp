#include "hrg_gyro/ros/triad_ros.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "hrg_gyro/TriadOutput.h"
#include "hrg_gyro/core/common/yaml_field.h"
#include "hrg_gyro/core/model/triad_file.h"
#include "hrg_gyro/ros/conversions.h"
#include "hrg_gyro/ros/diagnostics_timer.h"

namespace hrg_gyro {
namespace {

using diagnostic_msgs::DiagnosticStatus;

core::TriadCombinerSettings combinerSettings(ParameterReader& params) {
  core::TriadCombinerSettings s;
  s.stamp_tolerance = params.get("stamp_tolerance", s.stamp_tolerance);
  s.max_wait = params.get("max_wait", s.max_wait);
  s.max_pending = static_cast<std::size_t>(
      params.getAtLeast("max_pending", static_cast<int>(s.max_pending), 1, "samples per axis"));
  s.initial_rate_variance = params.get("initial_angular_velocity_variance", s.initial_rate_variance);
  s.max_rate = params.get("max_rate", s.max_rate);
  s.backward_reset = params.get("backward_reset", s.backward_reset);
  s.forward_jump = params.get("forward_jump", s.forward_jump);
  s.jump_persist = params.get("jump_persist", s.jump_persist);
  try {
    s.validate();
  } catch (const core::ConfigError& e) {
    throw std::invalid_argument("triad: ~" + e.key() + " " + e.problem());
  }
  return s;
}

std::shared_ptr<const core::TriadParameters> loadTriad(const std::string& path) {
  return std::make_shared<const core::TriadParameters>(core::loadTriadFile(path));
}

/// One line on the triad in force, for the log and the reload service.
std::string describe(const std::string& path, const core::TriadParameters& t) {
  char buf[512];
  std::snprintf(buf, sizeof buf,
                "%s: frame %s, axes %s %s %s, largest |M - I| %.3g, bias [%.3g %.3g %.3g] rad/s, calibration %s %s",
                path.c_str(), t.frame_id.c_str(), t.axes[0].c_str(), t.axes[1].c_str(), t.axes[2].c_str(),
                core::largestMisalignment(t.axis_to_body), t.bias(0), t.bias(1), t.bias(2),
                t.calibration.method.name().c_str(), t.calibration.time.c_str());
  return buf;
}

}  // namespace

TriadRos::TriadRos(ros::NodeHandle nh, ros::NodeHandle pnh)
    : nh_(nh), pnh_(pnh), params_(pnh, "triad"), updater_(nh, params_.checkDiagnosticPeriod(), pnh.getNamespace()) {
  triad_file_ = params_.get<std::string>("triad_file", "");
  if (triad_file_.empty())
    throw std::invalid_argument("triad: ~triad_file is required (the triad file: M, bias, axes)");
  std::shared_ptr<const core::TriadParameters> triad;
  try {
    triad = loadTriad(triad_file_);
  } catch (const core::ConfigError& e) {
    throw std::invalid_argument(std::string("triad: ~triad_file: ") + e.what());
  }
  combiner_ = std::make_unique<core::TriadCombiner>(combinerSettings(params_), triad);
  fixed_variance_ = params_.get("angular_velocity_variance", fixed_variance_);
  if (fixed_variance_ == 0.0 || !std::isfinite(fixed_variance_)) {
    throw std::invalid_argument(
        "triad: ~angular_velocity_variance must be positive ((rad/s)^2, for every axis), or negative for each "
        "axis's own from its imu/data_raw; 0 would claim perfect gyros");
  }
  const int max_unpaired = params_.getAtLeast("max_unpaired", 1000, 1, "outputs per axis");
  for (core::TriadVariancePairing& p : pairings_)
    p = core::TriadVariancePairing(static_cast<std::size_t>(max_unpaired));
  stall_timeout_ = params_.getPositive("stall_timeout", stall_timeout_, "s");
  expected_rate_ = params_.getPositive("expected_rate", expected_rate_, "Hz");
  const double tolerance = params_.getInRange("rate_tolerance", 0.1, 0.0, 1.0, "(relative)");
  min_rate_ = expected_rate_ * (1.0 - tolerance);
  max_rate_ = expected_rate_ * (1.0 + tolerance);
  // 5 s of 10 kHz per topic, as the processor's: a descheduled host delays samples, loses none.
  const int queue_size = params_.getAtLeast("queue_size", 50000, 1, "messages");
  const std::string hardware_id = params_.get<std::string>("hardware_id", "hrg_gyro_triad");

  output_pub_ = nh_.advertise<TriadOutput>("triad/output", queue_size);
  imu_pub_ = nh_.advertise<sensor_msgs::Imu>("imu/data_raw", queue_size);
  reload_srv_ = pnh_.advertiseService("reload", &TriadRos::onReload, this);

  updater_.setHardwareID(hardware_id);
  frequency_ = std::make_unique<diagnostic_updater::FrequencyStatus>(
      diagnostic_updater::FrequencyStatusParam(&min_rate_, &max_rate_, 0.0, 5), "rate");
  updater_.add(*frequency_);
  updater_.add("combination", this, &TriadRos::diagnoseTriad);
  updater_.add("triad file", this, &TriadRos::diagnoseFile);
  for (std::size_t a = 0; a < 3; ++a) {
    updater_.add("axis " + triad->axes[a],
                 [this, a](diagnostic_updater::DiagnosticStatusWrapper& stat) { diagnoseAxis(a, stat); });
    health_[a].reported_wall = ros::WallTime::now();
  }
  reported_wall_ = ros::WallTime::now();
  params_.warnAboutUnknownKeys();
  ready_.reserve(64);
  completed_.reserve(64);
  ros::NodeHandle input = input_.handle(nh_);
  const ros::TransportHints hints = ros::TransportHints().tcpNoDelay();
  for (std::size_t a = 0; a < 3; ++a) {
    const std::string& axis = triad->axes[a];
    subscribers_.push_back(input.subscribe<GyroOutput>(
        axis + "/output", queue_size, [this, a](const GyroOutput::ConstPtr& m) { onOutput(a, m); }, ros::VoidConstPtr(),
        hints));
    if (fixed_variance_ < 0.0) {
      subscribers_.push_back(input.subscribe<sensor_msgs::Imu>(
          axis + "/imu/data_raw", queue_size, [this, a](const sensor_msgs::Imu::ConstPtr& m) { onImu(a, m); },
          ros::VoidConstPtr(), hints));
    }
  }
  input_.start();
  diagnostics_timer_ = createDiagnosticsTimer(nh_, updater_);
  ROS_INFO("triad: %s", describe(triad_file_, *triad).c_str());
}

TriadRos::~TriadRos() {
  // First: the timer runs the diagnostic tasks, some of them members destroyed before it (a
  // FrequencyStatus called after its destruction aborted a test with "pure virtual method called").
  diagnostics_timer_.stop();
  for (ros::Subscriber& s : subscribers_) s.shutdown();
  input_.stop();
}

void TriadRos::onOutput(std::size_t axis, const GyroOutput::ConstPtr& msg) {
  std::lock_guard<std::mutex> lock(mutex_);
  AxisHealth& h = health_[axis];
  h.seen = true;
  h.last_wall = ros::WallTime::now();
  ++h.outputs;
  h.last_flags = msg->flags;
  core::AxisOutput output = toAxisOutput(*msg);
  ready_.clear();
  if (fixed_variance_ > 0.0) {
    output.rate_variance = fixed_variance_;
    ready_.push_back(output);
  } else {
    pairings_[axis].addOutput(output, &ready_);
  }
  combineReady(axis);
}

void TriadRos::onImu(std::size_t axis, const sensor_msgs::Imu::ConstPtr& msg) {
  std::lock_guard<std::mutex> lock(mutex_);
  ready_.clear();
  pairings_[axis].addVariance(toNanoseconds(msg->header.stamp), msg->angular_velocity_covariance[8], &ready_);
  combineReady(axis);
}

void TriadRos::combineReady(std::size_t axis) {
  completed_.clear();
  for (const core::AxisOutput& o : ready_) combiner_->add(axis, o, &completed_);
  const std::string& frame_id = combiner_->parameters().frame_id;
  for (const core::TriadBodySample& s : completed_) {
    if (s.flags & core::kTriadFlagReset) {
      ROS_WARN("triad: time went backwards (bag loop?): the triad restarts");
      frequency_->clear();  // its window of past ticks is in the future now
    }
    frequency_->tick();
    output_pub_.publish(boost::make_shared<TriadOutput>(toTriadOutputMessage(s, frame_id)));
    // REP-145 consumers integrate every Imu: a sample that measured nothing sends none.
    if (s.integrated()) imu_pub_.publish(boost::make_shared<sensor_msgs::Imu>(toImuMessage(s, frame_id)));
    last_stamp_ = toRosTime(s.stamp);
  }
}

bool TriadRos::onReload(std_srvs::Trigger::Request&, std_srvs::Trigger::Response& res) {
  std::shared_ptr<const core::TriadParameters> triad;
  std::string error;
  try {
    triad = loadTriad(triad_file_);
  } catch (const core::ConfigError& e) {
    error = e.what();  // names the key
  } catch (const std::exception& e) {
    error = e.what();
  }
  std::lock_guard<std::mutex> lock(mutex_);
  if (triad && triad->axes != combiner_->parameters().axes) {
    // The axes' topics are subscribed by name: another order or name needs a restart.
    error = "axes: [" + triad->axes[0] + ", " + triad->axes[1] + ", " + triad->axes[2] +
            "] differ from the axes in force; restart the node to change them";
  }
  if (error.empty()) {
    try {
      combiner_->setParameters(triad);
    } catch (const std::exception& e) {
      error = e.what();
    }
  }
  if (!error.empty()) {
    reload_.refuse(error, &res);
    return true;
  }
  reload_.loaded();
  res.success = true;
  // Which samples the new file applies to: those after the last one output (the swap is between
  // two samples); a client that compares outputs with the file needs it, however late the triad runs.
  char since[96];
  std::snprintf(since, sizeof since, " (in force after stamp %d.%09d)", last_stamp_.sec, last_stamp_.nsec);
  res.message = "loaded " + describe(triad_file_, *triad) + since;
  ROS_INFO("triad: %s", res.message.c_str());
  return true;
}

void TriadRos::diagnoseAxis(std::size_t axis, diagnostic_updater::DiagnosticStatusWrapper& stat) {
  std::lock_guard<std::mutex> lock(mutex_);
  AxisHealth& h = health_[axis];
  const core::TriadAxisCounters& c = combiner_->counters().axes[axis];
  const core::TriadVariancePairingCounters& p = pairings_[axis].counters();
  const std::string& name = combiner_->parameters().axes[axis];
  const ros::WallTime now = ros::WallTime::now();
  const double since = h.seen ? (now - h.last_wall).toSec() : INFINITY;
  const double span = (now - h.reported_wall).toSec();
  const double rate = span > 0.0 ? static_cast<double>(h.outputs - h.reported_outputs) / span : 0.0;
  const std::uint64_t missing = c.missing - h.reported.missing;
  const std::uint64_t flagged = c.flagged - h.reported.flagged;
  const std::uint64_t mismatched = c.mismatched - h.reported.mismatched;
  const std::uint64_t invalid = c.invalid - h.reported.invalid + c.duplicate - h.reported.duplicate + c.bad_stamp -
                                h.reported.bad_stamp + c.out_of_order - h.reported.out_of_order + c.stamp_jumps -
                                h.reported.stamp_jumps;
  if (!h.seen) {
    stat.summaryf(DiagnosticStatus::ERROR, "no output received yet on %s/output", name.c_str());
  } else if (since > stall_timeout_) {
    stat.summaryf(DiagnosticStatus::ERROR, "stalled: no output for %.2f s", since);
  } else if (missing + mismatched + invalid > 0) {
    stat.summaryf(DiagnosticStatus::WARN, "%lu stamps missing, %lu intervals mismatched, %lu outputs dropped",
                  static_cast<unsigned long>(missing), static_cast<unsigned long>(mismatched),
                  static_cast<unsigned long>(invalid));
  } else if (flagged > 0) {
    stat.summaryf(DiagnosticStatus::WARN, "%lu flagged outputs (last flags %u)", static_cast<unsigned long>(flagged),
                  static_cast<unsigned>(h.last_flags));
  } else {
    stat.summary(DiagnosticStatus::OK, "receiving");
  }
  stat.add("topic", nh_.resolveName(name + "/output"));
  stat.add("outputs per second", rate);
  stat.add("outputs", c.received);
  stat.add("seconds since last output", since);
  stat.add("missing stamps", c.missing);
  stat.add("intervals mismatched", c.mismatched);
  stat.add("flagged outputs", c.flagged);
  stat.add("last flags", static_cast<unsigned>(h.last_flags));
  stat.add("dropped (invalid)", c.invalid);
  stat.add("dropped (duplicate stamp)", c.duplicate);
  stat.add("dropped (zero stamp)", c.bad_stamp);
  stat.add("dropped (out-of-order stamp)", c.out_of_order);
  stat.add("dropped (stamp jump)", c.stamp_jumps);
  stat.add("times went backwards", c.epochs);
  stat.add("rate variance in force ((rad/s)^2)", combiner_->rateVariance(axis));
  stat.add("outputs without their variance", p.without_variance);
  stat.add("held waiting for their variance", pairings_[axis].heldOutputs());
  stat.add("held in the combiner", combiner_->pending(axis));
  h.reported = c;
  h.reported_outputs = h.outputs;
  h.reported_wall = now;
}

std::string TriadRos::whyNotCombined(const std::array<std::uint64_t, 3>& arrived) const {
  const core::TriadCounters& c = combiner_->counters();
  const std::array<std::string, 3>& names = combiner_->parameters().axes;
  const ros::WallTime now = ros::WallTime::now();
  std::string why;
  auto add = [&why](const std::string& text) { why += (why.empty() ? "" : "; ") + text; };
  std::size_t missing_axes = 0;
  for (std::size_t a = 0; a < 3; ++a) {
    const core::TriadAxisCounters& now_c = c.axes[a];
    const core::TriadAxisCounters& then = reported_.axes[a];
    const std::string& name = names[a];
    if (arrived[a] == 0) {
      if (health_[a].seen) {
        char seconds[32];
        std::snprintf(seconds, sizeof seconds, "%.2f s", (now - health_[a].last_wall).toSec());
        add("axis " + name + " sent nothing for " + seconds);
      } else {
        add("axis " + name + " sent nothing yet on " + nh_.resolveName(name + "/output"));
      }
      continue;
    }
    if (now_c.received == then.received) {
      add("axis " + name + ": " + std::to_string(arrived[a]) + " outputs held waiting for their variance on " +
          nh_.resolveName(name + "/imu/data_raw"));
      continue;
    }
    const std::uint64_t missing = now_c.missing - then.missing;
    const std::uint64_t mismatched = now_c.mismatched - then.mismatched;
    const std::uint64_t flagged = now_c.flagged - then.flagged;
    const std::uint64_t dropped = now_c.invalid - then.invalid + now_c.duplicate - then.duplicate;
    if (missing > 0) ++missing_axes;
    if (missing + mismatched + flagged + dropped == 0) continue;
    std::string parts;
    auto part = [&parts](std::uint64_t n, const char* what) {
      if (n > 0) parts += (parts.empty() ? "" : ", ") + std::to_string(n) + " " + what;
    };
    part(missing, "stamps missing");
    part(mismatched, "intervals mismatched");
    part(flagged, "flagged outputs");
    part(dropped, "outputs dropped (invalid or duplicate stamp)");
    add("axis " + name + ": " + parts);
  }
  // Every axis delivers, yet two or more lack the stamps the others have: their clocks differ.
  if (missing_axes >= 2 && arrived[0] > 0 && arrived[1] > 0 && arrived[2] > 0) {
    why = "the axes' stamps do not coincide (within ~stamp_tolerance): " + why;
  }
  return why;
}

void TriadRos::diagnoseTriad(diagnostic_updater::DiagnosticStatusWrapper& stat) {
  std::lock_guard<std::mutex> lock(mutex_);
  const core::TriadCounters& c = combiner_->counters();
  const ros::WallTime now = ros::WallTime::now();
  const double window = (now - reported_wall_).toSec();
  const std::uint64_t samples = c.samples - reported_.samples;
  const std::uint64_t integrated = c.integrated - reported_.integrated;
  const std::uint64_t gaps = c.gaps - reported_.gaps;
  std::array<std::uint64_t, 3> arrived{};
  double quiet = INFINITY;  // s since the newest output of any axis
  for (std::size_t a = 0; a < 3; ++a) {
    arrived[a] = health_[a].outputs - reported_outputs_[a];
    if (health_[a].seen) quiet = std::min(quiet, (now - health_[a].last_wall).toSec());
  }
  const bool inputs = arrived[0] + arrived[1] + arrived[2] > 0;
  if (inputs && integrated == 0) {
    // Outputs arrive but no body sample is published: the IMU is down, whatever each axis says.
    std::string why = whyNotCombined(arrived);
    if (why.empty()) why = "their samples are held, waiting for an axis (~max_wait)";
    char head[96];
    std::snprintf(head, sizeof head, "nothing combined in the last %.1f s while axis outputs arrive: ", window);
    stat.summary(DiagnosticStatus::ERROR, head + why);
  } else if (c.samples == 0) {
    stat.summary(DiagnosticStatus::ERROR, "no triad sample yet (waiting for all three axes)");
  } else if (!inputs && quiet > stall_timeout_) {
    stat.summaryf(DiagnosticStatus::ERROR, "stalled: no axis output for %.2f s, nothing combined", quiet);
  } else if (c.resets > reported_.resets) {
    stat.summary(DiagnosticStatus::WARN, "time went backwards: the triad restarted");
  } else if (gaps > 0) {
    const std::string why = whyNotCombined(arrived);
    stat.summary(DiagnosticStatus::WARN, std::to_string(gaps) + " of " + std::to_string(samples) +
                                             " samples are gaps (" +
                                             (why.empty() ? "an axis missing or flagged" : why) + ")");
  } else if (c.precessing > reported_.precessing) {
    stat.summary(DiagnosticStatus::WARN,
                 "an axis's wave is turned on command (FLAG_PRECESSING): its rate is not the body's, do not fuse");
  } else if (c.axis_flagged > reported_.axis_flagged) {
    stat.summary(DiagnosticStatus::WARN, "an axis's output carries a frequency flag");
  } else {
    stat.summary(DiagnosticStatus::OK, "combining");
  }
  stat.add("samples", c.samples);
  stat.add("combined", c.integrated);
  stat.add("combined since the last report", integrated);
  stat.add("gaps", c.gaps);
  stat.add("resets", c.resets);
  stat.add("axis flagged", c.axis_flagged);
  stat.add("precessing (an axis's wave turned on command)", c.precessing);
  stat.add("waited out (an axis too late)", c.timeouts);
  stat.add("overflowed (emitted as gaps)", c.non_finite);
  stat.add("stamps skipped by an axis (carried into the next)", c.carried);
  stat.add("late (after their stamp went out)", c.late);
  stat.add("last stamp", last_stamp_.toSec());
  reported_ = c;
  for (std::size_t a = 0; a < 3; ++a) reported_outputs_[a] = health_[a].outputs;
  reported_wall_ = now;
}

void TriadRos::diagnoseFile(diagnostic_updater::DiagnosticStatusWrapper& stat) {
  std::lock_guard<std::mutex> lock(mutex_);
  const core::TriadParameters& t = combiner_->parameters();
  if (reload_.lastRefused()) {
    stat.summary(DiagnosticStatus::WARN, reload_.refusalSummary());
  } else if (t.calibration.method.isNone()) {
    // A nominal triad takes the axes as the body axes: their misalignment (mrad) goes uncorrected.
    stat.summary(DiagnosticStatus::WARN, "nominal triad (calibration method: none): misalignment not corrected");
  } else {
    stat.summary(DiagnosticStatus::OK, "triad file loaded");
  }
  stat.add("triad file", triad_file_);
  stat.add("frame_id", t.frame_id);
  stat.add("axes", t.axes[0] + " " + t.axes[1] + " " + t.axes[2]);
  for (int i = 0; i < 3; ++i) {
    char row[128];
    std::snprintf(row, sizeof row, "%.9g %.9g %.9g", t.axis_to_body(i, 0), t.axis_to_body(i, 1), t.axis_to_body(i, 2));
    stat.add("M row " + std::to_string(i + 1), row);
  }
  char bias[128];
  std::snprintf(bias, sizeof bias, "%.6g %.6g %.6g", t.bias(0), t.bias(1), t.bias(2));
  stat.add("bias (rad/s)", bias);
  stat.add("calibration method", t.calibration.method.name());
  stat.add("calibration time", t.calibration.time);
  reload_.addCounts(stat);
}

}  // namespace hrg_gyro
