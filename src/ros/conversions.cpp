#include "hrg_gyro/ros/conversions.h"

#include <algorithm>
#include <cmath>

namespace hrg_gyro {

core::ChannelSample fromMessage(const ChannelAmplitudes& msg) {
  core::ChannelSample in;
  in.stamp = toNanoseconds(msg.header.stamp);
  in.z << msg.c_in, msg.c_quad, msg.s_in, msg.s_quad;
  in.frequency = msg.frequency;
  in.temperature = msg.temperature;
  return in;
}

WaveState toWaveMessage(const ChannelAmplitudes& input, const core::WaveState& w, const std::string& frame_id) {
  WaveState m;
  m.header = input.header;
  m.header.frame_id = frame_id;
  m.theta = w.theta;
  m.amplitude = w.amplitude;
  m.quadrature = w.quadrature;
  m.phase = w.phase;
  m.energy = w.energy;
  m.quadrature_product = w.quadrature_product;
  m.phase_error = w.phase_error;
  m.frequency = input.frequency;
  m.temperature = input.temperature;
  return m;
}

GyroOutput toOutputMessage(const std_msgs::Header& header, const core::ProcessorResult& r) {
  const core::AngleIncrement& inc = r.increment;
  GyroOutput out;
  out.header = header;
  out.dt = inc.dt;
  out.dtheta = inc.dtheta;
  out.dalpha = inc.dalpha;
  out.dalpha_earth_fixed = inc.dalpha_earth_fixed;
  out.alpha = r.alpha;
  out.rate = inc.dt > 0.0 ? inc.dalpha / inc.dt : 0.0;
  out.theta_mid = inc.theta_mid;
  out.frequency = inc.frequency;
  out.scale_factor = inc.scale_factor;
  out.drift = inc.drift;
  out.rejected_before = r.rejected_before;
  out.flags = r.flags;
  return out;
}

core::AxisOutput toAxisOutput(const GyroOutput& msg) {
  core::AxisOutput o;
  o.stamp = toNanoseconds(msg.header.stamp);
  o.dt = msg.dt;
  o.dalpha = msg.dalpha;
  o.flags = msg.flags;
  return o;
}

TriadOutput toTriadOutputMessage(const core::TriadBodySample& s, const std::string& frame_id) {
  TriadOutput m;
  m.header.stamp = toRosTime(s.stamp);
  m.header.frame_id = frame_id;
  m.dt = s.dt;
  m.delta_angle.x = s.delta_angle.x();
  m.delta_angle.y = s.delta_angle.y();
  m.delta_angle.z = s.delta_angle.z();
  m.angular_velocity.x = s.angular_velocity.x();
  m.angular_velocity.y = s.angular_velocity.y();
  m.angular_velocity.z = s.angular_velocity.z();
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) m.angular_velocity_covariance[3 * i + j] = s.covariance(i, j);
  }
  m.flags = s.flags;
  return m;
}

sensor_msgs::Imu toImuMessage(const core::TriadBodySample& s, const std::string& frame_id) {
  sensor_msgs::Imu m;
  m.header.stamp = toRosTime(s.stamp);
  m.header.frame_id = frame_id;
  // REP-145: a gyro triad measures neither orientation nor acceleration.
  m.orientation_covariance[0] = -1.0;
  m.linear_acceleration_covariance[0] = -1.0;
  m.angular_velocity.x = s.angular_velocity.x();
  m.angular_velocity.y = s.angular_velocity.y();
  m.angular_velocity.z = s.angular_velocity.z();
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) m.angular_velocity_covariance[3 * i + j] = s.covariance(i, j);
  }
  return m;
}

ChannelAmplitudes toChannelsMessage(const core::SimulationSample& s, const ros::Time& stamp, std::uint32_t seq,
                                    const std::string& frame_id) {
  ChannelAmplitudes m;
  m.header.seq = seq;
  // A scheduled stamp glitch moves this message's stamp only (never below 1 ns).
  m.header.stamp = s.channels_stamp_offset == 0
                       ? stamp
                       : toRosTime(std::max<core::Nanoseconds>(1, toNanoseconds(stamp) + s.channels_stamp_offset));
  m.header.frame_id = frame_id;
  m.c_in = s.z[core::kAc];
  m.c_quad = s.z[core::kBc];
  m.s_in = s.z[core::kAs];
  m.s_quad = s.z[core::kBs];
  m.frequency = s.frequency;
  m.temperature = s.temperature;
  m.periods = s.periods;
  return m;
}

TurntableState toTurntableMessage(const core::TurntableLogRecord& r, core::Nanoseconds origin,
                                  const std::string& frame_id) {
  TurntableState m;
  m.header.seq = static_cast<std::uint32_t>(r.index);
  // A zero stamp is what a glitched controller sends, whatever the clock's origin.
  m.header.stamp = r.stamp == 0 ? ros::Time() : toRosTime(origin + r.stamp);
  m.header.frame_id = frame_id;
  m.angle = r.angle;
  m.rate = r.rate;
  return m;
}

GroundTruth toTruthMessage(const core::SimulationSample& s, const std_msgs::Header& header) {
  GroundTruth t;
  t.header = header;
  t.table_angle = s.truth.table_angle;
  t.table_rate = s.truth.table_rate;
  t.inertial_angle = s.truth.inertial_angle;
  t.inertial_rate = s.truth.inertial_rate;
  t.theta = s.truth.theta;
  t.amplitude = s.truth.amplitude;
  t.quadrature = s.truth.quadrature;
  t.phase = s.truth.phase;
  t.frequency = s.truth.frequency;
  t.temperature = s.truth.temperature;
  t.generator = s.truth.generator;
  t.segment = s.truth.segment ? *s.truth.segment : std::string();
  return t;
}

const char* const kScheduledPrecessionSource = "schedule";

void updatePrecessionSource(const core::SimulationSample& s, const std::string& commander, std::string* source) {
  for (const core::AppliedPrecession& a : s.precession_commands) {
    *source = a.scheduled ? kScheduledPrecessionSource : commander;
  }
}

PrecessionState toPrecessionStateMessage(const core::SimulationSample& s, const std_msgs::Header& header,
                                         const std::string& source) {
  PrecessionState m;
  m.header = header;
  m.rate = s.precession.rate;
  m.angle = s.precession.angle;
  m.commands = static_cast<std::uint32_t>(s.precession.commands);
  m.source = source;
  return m;
}

PrecessionCommand toPrecessionCommandMessage(const core::AppliedPrecession& command, const ros::Time& stamp,
                                             const std::string& frame_id) {
  PrecessionCommand m;
  m.header.stamp = stamp;
  m.header.frame_id = frame_id;
  m.rate = command.rate;
  return m;
}

namespace {

geometry_msgs::Quaternion toQuaternionMessage(const Eigen::Quaterniond& q) {
  geometry_msgs::Quaternion m;
  m.w = q.w();
  m.x = q.x();
  m.y = q.y();
  m.z = q.z();
  return m;
}

}  // namespace

FixturePosition toFixtureMessage(const core::TriadSample& s, const ros::Time& stamp, const std::string& frame_id) {
  FixturePosition m;
  m.header.seq = static_cast<std::uint32_t>(s.index);
  m.header.stamp = stamp;
  m.header.frame_id = frame_id;
  m.index = s.fixture.index;
  m.name = s.fixture.name ? *s.fixture.name : std::string();
  m.body_to_table = toQuaternionMessage(s.fixture.body_to_table);
  m.locked = s.fixture.locked;
  return m;
}

BodyTruth toBodyTruthMessage(const core::TriadSample& s, const ros::Time& stamp, const std::string& frame_id) {
  BodyTruth m;
  m.header.seq = static_cast<std::uint32_t>(s.index);
  m.header.stamp = stamp;
  m.header.frame_id = frame_id;
  m.angular_velocity.x = s.body.angular_velocity.x();
  m.angular_velocity.y = s.body.angular_velocity.y();
  m.angular_velocity.z = s.body.angular_velocity.z();
  m.body_to_table = toQuaternionMessage(s.body.body_to_table);
  m.body_to_enu = toQuaternionMessage(Eigen::Quaterniond(s.body.body_to_enu).normalized());
  m.position = s.body.position;
  return m;
}

sensor_msgs::Imu toAccelerometerMessage(const core::TriadSample& s, const ros::Time& stamp,
                                        const core::TriadAccelerometerConfig& accelerometer) {
  sensor_msgs::Imu m;
  m.header.seq = static_cast<std::uint32_t>(s.index);
  m.header.stamp = stamp;
  m.header.frame_id = accelerometer.frame_id;
  m.orientation_covariance[0] = -1.0;
  m.angular_velocity_covariance[0] = -1.0;
  m.linear_acceleration.x = s.accelerometer.specific_force.x();
  m.linear_acceleration.y = s.accelerometer.specific_force.y();
  m.linear_acceleration.z = s.accelerometer.specific_force.z();
  const double variance = accelerometer.noise * accelerometer.noise;
  for (int i = 0; i < 3; ++i) m.linear_acceleration_covariance[4 * i] = variance;
  return m;
}

HarmonicEstimate toMessage(const core::HarmonicFitResult& fit, double frequency) {
  HarmonicEstimate m;
  m.orders.assign(fit.orders.begin(), fit.orders.end());
  m.frequency = frequency;
  m.mean = fit.mean;
  m.mean_std = fit.mean_std;
  m.cos = fit.cos;
  m.cos_std = fit.cos_std;
  m.sin = fit.sin;
  m.sin_std = fit.sin_std;
  m.residual_rms = fit.residual_rms;
  m.points = static_cast<std::uint32_t>(fit.points);
  return m;
}

core::HarmonicFitResult fromMessage(const HarmonicEstimate& m) {
  core::HarmonicFitResult f;
  f.ok = true;
  f.orders.assign(m.orders.begin(), m.orders.end());
  f.mean = m.mean;
  f.mean_std = m.mean_std;
  f.cos = m.cos;
  f.cos_std = m.cos_std;
  f.sin = m.sin;
  f.sin_std = m.sin_std;
  f.residual_rms = m.residual_rms;
  f.points = m.points;
  return f;
}

std::vector<QualityGate> toMessages(const std::vector<core::GateResult>& gates) {
  std::vector<QualityGate> out;
  out.reserve(gates.size());
  for (const core::GateResult& g : gates) {
    QualityGate q;
    q.name = g.name;
    q.passed = g.passed;
    q.value = g.value;
    q.limit = g.limit;
    q.message = g.message;
    out.push_back(q);
  }
  return out;
}

CalibrationResult toMessage(const core::CalibrationOutcome& o, bool written, const std::string& file,
                            const ros::Time& stamp) {
  CalibrationResult m;
  m.header.stamp = stamp;
  m.method = core::nameOf(o.method);
  m.accepted = o.accepted;
  m.written = written;
  m.reason = o.reason;
  m.parameter_file = file;
  for (std::size_t i = 0; i < o.scale_factor.size(); ++i) {
    m.scale_factor.push_back(toMessage(o.scale_factor[i], i < o.frequency_nodes.size() ? o.frequency_nodes[i] : NAN));
  }
  for (std::size_t i = 0; i < o.drift.size(); ++i) {
    m.drift.push_back(toMessage(o.drift[i], i < o.frequency_nodes.size() ? o.frequency_nodes[i] : NAN));
  }
  for (int i = 0; i < 4; ++i) {
    m.correction[i] = o.parameters.correction.p[i];
    m.correction_std[i] = o.has_correction ? o.correction.standard_error[i] : 0.0;
  }
  m.coverage = o.coverage;
  m.smoothing_factor = o.smoothing_factor;
  m.error_bound = o.error_bound;
  m.nonlinearity_ppm = o.nonlinearity_ppm;
  m.duration = o.duration;
  m.samples = o.samples;
  for (const core::GroupSummary& g : o.plateaus) {
    PlateauSummary p;
    p.rate = g.rate;
    p.rate_std = g.rate_std;
    p.duration = g.duration;
    p.samples = g.samples;
    p.coverage = g.coverage;
    p.turns = g.turns;
    m.plateaus.push_back(p);
  }
  m.gates = toMessages(o.gates);
  for (const core::DefectDiagnosis& d : o.diagnosis) {
    DefectDiagnosis x;
    x.frequency = d.frequency;
    x.valid = d.valid;
    x.note = d.note;
    x.gain_mismatch = d.gain_mismatch;
    x.gain_mismatch_std = d.gain_mismatch_std;
    x.misplacement_difference = d.misplacement_difference;
    x.misplacement_difference_std = d.misplacement_difference_std;
    x.pickoff_ratio = d.pickoff_ratio;
    x.pickoff_ratio_std = d.pickoff_ratio_std;
    x.quadrature_factor = d.quadrature_factor;
    for (int i = 0; i < 4; ++i) {
      x.current_p[i] = d.current_correction.p[i];
      x.recommended_p[i] = d.recommended_correction.p[i];
      x.recommended_p_std[i] = d.recommended_correction_std[i];
    }
    m.diagnosis.push_back(x);
  }
  m.quadrature_ratio = o.quadrature_ratio;
  return m;
}

core::CalibrationOutcome fromMessage(const CalibrationResult& m) {
  core::CalibrationOutcome o;
  o.method = core::parseCalibrationMethod(m.method);
  o.accepted = m.accepted;
  o.reason = m.reason;
  for (const HarmonicEstimate& h : m.scale_factor) {
    o.scale_factor.push_back(fromMessage(h));
    if (!std::isnan(h.frequency)) o.frequency_nodes.push_back(h.frequency);
  }
  for (const HarmonicEstimate& h : m.drift) o.drift.push_back(fromMessage(h));
  for (int i = 0; i < 4; ++i) o.parameters.correction.p[i] = m.correction[i];
  o.coverage = m.coverage;
  o.smoothing_factor = m.smoothing_factor;
  o.error_bound = m.error_bound;
  o.nonlinearity_ppm = m.nonlinearity_ppm;
  o.duration = m.duration;
  o.samples = m.samples;
  for (const PlateauSummary& p : m.plateaus) {
    o.plateaus.push_back({p.rate, p.rate_std, p.duration, p.samples, p.coverage, p.turns});
  }
  for (const QualityGate& q : m.gates) o.gates.push_back({q.name, q.passed != 0, q.value, q.limit, q.message});
  return o;
}

namespace {

/// A matrix as a message's row-major float64[9] (element (i, j) at 3 i + j).
void toArray(const Eigen::Matrix3d& m, boost::array<double, 9>* out) {
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) (*out)[3 * i + j] = m(i, j);
}

void toArray(const Eigen::Vector3d& v, boost::array<double, 3>* out) {
  for (int i = 0; i < 3; ++i) (*out)[i] = v(i);
}

}  // namespace

TriadCalibrationResult toMessage(const core::TriadOutcome& o) {
  TriadCalibrationResult r;
  r.header.frame_id = o.triad.frame_id;
  r.accepted = o.accepted;
  r.reason = o.reason;
  r.axes.assign(o.axis_names.begin(), o.axis_names.end());
  toArray(o.triad.axis_to_body, &r.axis_to_body);
  toArray(o.triad.axis_to_body_std, &r.axis_to_body_std);
  toArray(o.body_to_axis, &r.body_to_axis);
  toArray(o.triad.bias, &r.bias);
  toArray(o.triad.bias_std, &r.bias_std);
  r.bias_estimated = o.bias_estimated;
  r.positions_fitted = static_cast<std::uint32_t>(o.positions_fitted);
  for (int i = 0; i < 3; ++i) {
    r.axis_accepted[i] = o.axes[i].accepted;
    r.axis_nonlinearity_ppm[i] = o.axes[i].nonlinearity_ppm;
    r.axis_reasons.push_back(o.axes[i].accepted ? std::string() : o.axes[i].reason);
  }
  r.gates = toMessages(o.gates);
  r.notes = o.notes;
  return r;
}

core::FixtureRecord fromMessage(const FixturePosition& msg) {
  core::FixtureRecord r;
  r.stamp = toNanoseconds(msg.header.stamp);
  r.index = msg.index;
  r.name = msg.name;
  r.body_to_table =
      Eigen::Quaterniond(msg.body_to_table.w, msg.body_to_table.x, msg.body_to_table.y, msg.body_to_table.z);
  r.locked = msg.locked;
  return r;
}

core::TriadBodySample fromMessage(const TriadOutput& m) {
  core::TriadBodySample s;
  s.stamp = toNanoseconds(m.header.stamp);
  s.dt = m.dt;
  s.delta_angle = Eigen::Vector3d(m.delta_angle.x, m.delta_angle.y, m.delta_angle.z);
  s.angular_velocity = Eigen::Vector3d(m.angular_velocity.x, m.angular_velocity.y, m.angular_velocity.z);
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) s.covariance(i, j) = m.angular_velocity_covariance[3 * i + j];
  }
  s.flags = m.flags;
  return s;
}

core::IndexerRecord fromMessage(const TurntableState& m) {
  core::IndexerRecord r;
  r.stamp = toNanoseconds(m.header.stamp);
  r.angle = m.angle;
  r.rate = m.rate;
  return r;
}

core::AccelerometerRecord fromAccelerometerMessage(const sensor_msgs::Imu& m) {
  core::AccelerometerRecord r;
  r.stamp = toNanoseconds(m.header.stamp);
  r.specific_force = Eigen::Vector3d(m.linear_acceleration.x, m.linear_acceleration.y, m.linear_acceleration.z);
  return r;
}

core::ImuSample fromImuMessage(const sensor_msgs::Imu& m) {
  core::ImuSample s;
  s.stamp = toNanoseconds(m.header.stamp);
  s.angular_velocity = Eigen::Vector3d(m.angular_velocity.x, m.angular_velocity.y, m.angular_velocity.z);
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) s.angular_velocity_covariance(i, j) = m.angular_velocity_covariance[3 * i + j];
  }
  s.linear_acceleration = Eigen::Vector3d(m.linear_acceleration.x, m.linear_acceleration.y, m.linear_acceleration.z);
  s.has_acceleration = m.linear_acceleration_covariance[0] != -1.0;
  return s;
}

core::PrecessionStateRecord fromMessage(const PrecessionState& m) {
  core::PrecessionStateRecord r;
  r.stamp = toNanoseconds(m.header.stamp);
  r.rate = m.rate;
  r.angle = m.angle;
  return r;
}

namespace {

template <class Array>
void copyMatrix(const Eigen::Matrix3d& matrix, Array* out) {
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) (*out)[3 * i + j] = matrix(i, j);
  }
}

}  // namespace

AlignmentResult toMessage(const core::AlignmentResult& r, const std::string& frame_id) {
  AlignmentResult m;
  m.header.stamp = toRosTime(r.end);
  m.header.frame_id = frame_id;
  m.accepted = r.accepted;
  m.gate = r.gate;
  m.reason = r.reason;
  m.mode = core::toString(r.mode);
  m.single_gyro = r.single_gyro;
  m.frame = r.frame;
  m.heading_deg = r.heading;
  m.heading_sigma_deg = r.heading_sigma;
  m.roll = r.attitude.roll;
  m.pitch = r.attitude.pitch;
  m.yaw = r.attitude.yaw;
  m.orientation = toQuaternionMessage(r.orientation);
  copyMatrix(r.covariance_enu, &m.orientation_covariance);
  copyMatrix(r.covariance_rpy, &m.euler_covariance);
  m.body_orientation = toQuaternionMessage(r.body_orientation);
  m.window_start = toRosTime(r.start);
  m.window_end = toRosTime(r.end);
  m.seconds = r.seconds;
  m.samples = r.samples;
  const core::HeadingErrorBudget& b = r.budget;
  m.budget_white_angle_noise = b.white_angle_noise;
  m.budget_angle_random_walk = b.angle_random_walk;
  m.budget_noise = b.noise;
  m.budget_residual_bias = b.residual_bias;
  m.budget_drift_harmonics = b.drift_harmonics;
  m.budget_bias_random_walk = b.bias_random_walk;
  m.budget_level = b.level;
  m.budget_indexer = b.indexer;
  m.budget_total = b.total;
  m.horizontal_rate = r.horizontal_rate;
  m.horizontal_rate_std = r.horizontal_rate_std;
  m.expected_horizontal_rate = b.horizontal_earth_rate;
  m.latitude = b.latitude;
  m.scatter = r.scatter;
  m.worst_motion = r.worst_motion;
  for (const core::AlignmentSegment& g : r.segments) {
    m.segment_start.push_back(g.start);
    m.segment_end.push_back(g.end);
    m.segment_indexer_angle.push_back(g.indexer_angle);
    m.segment_commanded_rate.push_back(g.commanded_rate);
    double worst = 0.0;
    for (std::size_t c = 0; c < g.rms.size() && c < g.predicted_rms.size(); ++c) {
      if (g.predicted_rms[c] > 0.0) worst = std::max(worst, g.rms[c] / g.predicted_rms[c]);
    }
    m.segment_rms_ratio.push_back(worst);
  }
  m.last_sample = toRosTime(r.last_sample);
  m.estimator = r.estimator;
  m.estimator_reason = r.estimator_reason;
  m.noise_sources = r.noise_sources;
  for (const core::BaseStepRecord& s : r.base_steps) {
    m.step_time.push_back(s.time);
    for (int i = 0; i < 3; ++i) m.step_rotation.push_back(s.rotation(i));
  }
  m.excluded_seconds = r.excluded_seconds;
  m.low_frequency_scatter = r.low_frequency_scatter;
  m.tracking_heading_deg = r.tracking_heading;
  m.tracking_heading_sigma_deg = r.tracking_heading_sigma;
  m.estimator_difference = r.estimator_difference;
  for (const core::EarthCheck& c : r.earth_checks) {
    m.check_name.push_back(c.name);
    m.check_measured.push_back(c.measured);
    m.check_expected.push_back(c.expected);
    m.check_sigma.push_back(c.sigma);
    m.check_passed.push_back(c.passed);
  }
  return m;
}

sensor_msgs::Imu toAlignmentImuMessage(const core::AlignmentResult& r, const std::string& frame_id) {
  sensor_msgs::Imu m;
  m.header.stamp = toRosTime(r.last_sample > 0 ? r.last_sample : r.end);
  m.header.frame_id = frame_id;
  m.orientation = toQuaternionMessage(r.body_orientation);
  copyMatrix(r.covariance_enu, &m.orientation_covariance);
  m.angular_velocity_covariance[0] = -1.0;
  m.linear_acceleration_covariance[0] = -1.0;
  return m;
}

sensor_msgs::Imu toHeldImuMessage(const core::AttitudeHold& hold, const core::TriadBodySample& sample,
                                  const std::string& frame_id) {
  sensor_msgs::Imu m = toImuMessage(sample, frame_id);
  m.orientation = toQuaternionMessage(hold.orientation());
  copyMatrix(hold.covariance(), &m.orientation_covariance);
  return m;
}

}  // namespace hrg_gyro
