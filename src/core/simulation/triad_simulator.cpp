#include "hrg_gyro/core/simulation/triad_simulator.h"

#include <cmath>

#include "hrg_gyro/core/alignment/local_level.h"

namespace hrg_gyro {
namespace core {
namespace {

/// The accelerometer's noise stream: switching it on changes no other draw.
constexpr std::uint64_t kAccelerometerStream = 0xbb67ae8584caa73bULL;

}  // namespace

Eigen::Vector3d specificForceAtRest(const Eigen::Matrix3d& body_to_enu, const Eigen::Matrix3d& accelerometer_to_body) {
  return (body_to_enu * accelerometer_to_body).transpose() * Eigen::Vector3d(0.0, 0.0, kStandardGravity);
}

/// Axis i's sensed rate A_i . omega_body. Its own copy of the motion: the motions' evaluation cursors
/// then follow one axis's times each.
class TriadSimulator::AxisInput : public AxisRateInput {
 public:
  AxisInput(const TriadSimulationConfig& config, const Eigen::RowVector3d& direction)
      : motion_(config), direction_(direction) {}
  double rateAt(double t) const override { return direction_ * motion_.angularVelocityAt(t); }

 private:
  TriadMotion motion_;
  Eigen::RowVector3d direction_;
};

TriadSimulator::TriadSimulator(const TriadSimulationConfig& config)
    : config_(config),
      motion_(config_),
      logger_(config_.turntable.log, config_.seed),
      accelerometer_noise_(config_.seed ^ kAccelerometerStream),
      accelerometer_misalignment_(rotationFromVector(config_.accelerometer.misalignment).transpose()) {
  const Eigen::Matrix3d a = config_.bodyToAxis();
  for (int i = 0; i < 3; ++i) {
    inputs_[i] = std::make_unique<AxisInput>(config_, a.row(i));
    axes_[i] = std::make_unique<GyroSimulator>(config_.axisScenario(i), inputs_[i].get());
  }
  for (const FixturePositionConfig& p : config_.positions) nominal_.emplace_back(p.nominal);
}

TriadSimulator::~TriadSimulator() = default;

void TriadSimulator::logTurntable(double t_center, Nanoseconds stamp, const TriadBodyState& state, TriadSample* out) {
  out->turntable.clear();
  const double log_rate = config_.turntable.log.rate;
  if (log_rate == 0.0) {
    // One record with the sample, stamped like it (as a single gyro's default log).
    logger_.log(t_center, stamp, state.table_angle, state.table_rate, &out->turntable);
    return;
  }
  for (;; ++next_log_) {
    const double t = static_cast<double>(next_log_) / log_rate;
    if (t > t_center) break;
    double angle, rate;
    config_.table_profile.evaluate(t, &angle, &rate);
    logger_.log(t, toNanoseconds(config_.start_time + t), angle, rate, &out->turntable);
  }
}

void TriadSimulator::logFixture(double t_center, const TriadBodyState& state, TriadSample* out) {
  FixtureState& f = out->fixture;
  f.index = static_cast<std::uint32_t>(state.position);
  f.name = &config_.positions[state.position].name;
  f.body_to_table = nominal_[state.position];
  f.locked = state.locked;
  const bool changed = !fixture_logged_once_ || f.index != last_fixture_.index || f.locked != last_fixture_.locked;
  // Half a sample early: the rounding of the window centres must not skip a second.
  const bool due = t_center - last_fixture_log_ >= kFixtureLogPeriod - 0.5 * config_.outputPeriod();
  out->fixture_logged = changed || due;
  if (out->fixture_logged) last_fixture_log_ = t_center;
  fixture_logged_once_ = true;
  last_fixture_ = f;
}

void TriadSimulator::measureAcceleration(double t_start, double t_end, const TriadBodyState& state, TriadSample* out) {
  using Convention = TriadAccelerometerConfig::Convention;
  const TriadAccelerometerConfig& a = config_.accelerometer;
  out->accelerometer.present = a.enabled;
  if (!a.enabled) return;
  Eigen::Vector3d noise;
  for (int j = 0; j < 3; ++j) noise[j] = accelerometer_noise_.next();  // in order
  // Steps 1-2 (triad_simulator.h); without vibration (0, 0, g) is exactly specificForceAtRest's.
  Eigen::Vector3d enu(0.0, 0.0, kStandardGravity);
  if (motion_.base().enabled()) enu += motion_.base().meanAccelerationOver(t_start, t_end);
  Eigen::Vector3d f = (state.body_to_enu * a.accelerometer_to_body).transpose() * enu;
  // Steps 3-6, each skipped when it is the identity: older records keep their bits (an identity
  // product would turn -0 into +0).
  if (a.misalignment != Eigen::Vector3d::Zero()) f = accelerometer_misalignment_ * f;
  if (a.scale != Eigen::Vector3d::Zero()) f = (Eigen::Vector3d::Ones() + a.scale).cwiseProduct(f);
  if (a.axis_signs != Eigen::Vector3d::Ones()) f = a.axis_signs.cwiseProduct(f);
  if (a.convention == Convention::kGravity) f = -f;
  f = f + a.bias + a.noise * noise;
  if (a.quantum > 0.0) {
    for (int j = 0; j < 3; ++j) f[j] = a.quantum * std::round(f[j] / a.quantum);
  }
  out->accelerometer.specific_force = f;
}

bool TriadSimulator::next(TriadSample* out) {
  if (done()) return false;
  const double t_start = elapsed();
  for (int i = 0; i < 3; ++i) axes_[i]->next(&out->axes[i]);
  out->index = out->axes[0].index;
  out->stamp = out->axes[0].stamp;
  // The centre of the window, computed as each axis computes it for its stamp.
  const double t_center = 0.5 * (t_start + elapsed());
  const TriadBodyState state = motion_.stateAt(t_center);
  out->body.angular_velocity = state.angular_velocity;
  out->body.body_to_table = Eigen::Quaterniond(state.body_to_table).normalized();
  out->body.body_to_enu = Eigen::Quaterniond(state.body_to_enu).normalized();
  out->body.position = static_cast<std::uint32_t>(state.position);
  logTurntable(t_center, out->stamp, state, out);
  logFixture(t_center, state, out);
  measureAcceleration(t_start, elapsed(), state, out);
  return true;
}

}  // namespace core
}  // namespace hrg_gyro
