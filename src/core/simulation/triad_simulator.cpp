#include "hrg_gyro/core/simulation/triad_simulator.h"

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
      accelerometer_noise_(config_.seed ^ kAccelerometerStream) {
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

void TriadSimulator::measureGravity(const TriadBodyState& state, TriadSample* out) {
  const TriadAccelerometerConfig& a = config_.accelerometer;
  out->accelerometer.present = a.enabled;
  if (!a.enabled) return;
  Eigen::Vector3d noise;
  for (int j = 0; j < 3; ++j) noise[j] = accelerometer_noise_.next();  // in order
  out->accelerometer.specific_force =
      specificForceAtRest(state.body_to_enu, a.accelerometer_to_body) + a.bias + a.noise * noise;
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
  measureGravity(state, out);
  return true;
}

}  // namespace core
}  // namespace hrg_gyro
