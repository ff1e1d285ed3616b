// The simulated triad on its rate table (TriadSimulationConfig), one output sample at a time: three
// signal-level gyros (GyroSimulator each, its own defects and noise streams), each sensing
// A_i . omega_body through the axis-rate input (TriadMotion gives omega_body), sharing the output
// stamps; one table log (TurntableLogger, as a single gyro's); the fixture's position log; and the
// truth of the body and of each axis.
//
// Per output sample (stamped at the centre of its demodulation window, like a single gyro's):
//   axes[i]    axis i's SimulationSample: channels, and its truth with inertial_rate = A_i . omega_body
//              and inertial_angle = its integral from the start; table_angle and table_rate are the table's
//   turntable  the table records logged since the previous sample (one per sample by default)
//   fixture    the fixture's state at the sample (position index and name, nominal body_to_table,
//              locked), `fixture_logged` when it is to be published: at the first sample, whenever the
//              position or the lock changed since the previous sample, and otherwise every second
//   body       the body's truth at the sample: omega_body, the true body_to_table (fixture error and
//              wobble included) and body_to_enu (the base's D included), the position index
//   accelerometer  with `triad/accelerometer` enabled: its record at the sample, from a stream of its
//              own for the noise, in this order (each step left out when its key is not given, so a
//              scenario without them is bit for bit what it was):
//                1. f_body = C^T ((0, 0, g) + a), C the true body_to_enu at the sample's centre, g
//                   standard gravity, a the base's vibration averaged over the sample's interval
//                   (BaseMotion::meanAccelerationOver: what a delta-velocity over dt reads)
//                2. into its frame through its mounting: accelerometer_to_body^T f_body
//                3. misalignment: Rot(rho)^T f
//                4. scale: (1 + s_j) f_j
//                5. axis signs: sign_j f_j
//                6. convention gravity: -f
//                7. + bias + noise (white, 1 sigma `noise`)
//                8. quantum Q: Q round(f_j / Q) (halves away from zero)
//              The vibration reaches the accelerometer only: the gyros sense the base's rotation.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "hrg_gyro/core/simulation/gyro_simulator.h"
#include "hrg_gyro/core/simulation/triad_motion.h"
#include "hrg_gyro/core/simulation/triad_simulation_config.h"

namespace hrg_gyro {
namespace core {

/// How often the fixture's position is logged while nothing changes, s.
constexpr double kFixtureLogPeriod = 1.0;

struct FixtureState {
  std::uint32_t index = 0;                                            ///< position in the session plan
  const std::string* name = nullptr;                                  ///< owned by the simulator's config
  Eigen::Quaterniond body_to_table = Eigen::Quaterniond::Identity();  ///< nominal (as planned)
  bool locked = true;                                                 ///< false: being moved into `index`
};

struct TriadBodyTruth {
  Eigen::Vector3d angular_velocity = Eigen::Vector3d::Zero();         ///< rad/s, inertial, body frame
  Eigen::Quaterniond body_to_table = Eigen::Quaterniond::Identity();  ///< true
  Eigen::Quaterniond body_to_enu = Eigen::Quaterniond::Identity();    ///< true attitude (REP-103)
  std::uint32_t position = 0;
};

struct AccelerometerSample {
  bool present = false;                                      ///< the scenario has an accelerometer
  Eigen::Vector3d specific_force = Eigen::Vector3d::Zero();  ///< m/s^2, its frame (REP-145: +g up at rest)
};

/// The specific force an accelerometer mounted by `accelerometer_to_body` on a body at `body_to_enu`
/// measures at rest, without bias or noise: (body_to_enu accelerometer_to_body)^T (0, 0, g), m/s^2.
Eigen::Vector3d specificForceAtRest(const Eigen::Matrix3d& body_to_enu, const Eigen::Matrix3d& accelerometer_to_body);

struct TriadSample {
  std::uint64_t index = 0;
  Nanoseconds stamp = 0;  ///< the axes' common stamp
  std::array<SimulationSample, 3> axes;
  std::vector<TurntableLogRecord> turntable;
  FixtureState fixture;
  bool fixture_logged = false;
  TriadBodyTruth body;
  AccelerometerSample accelerometer;
};

class TriadSimulator {
 public:
  explicit TriadSimulator(const TriadSimulationConfig& config);
  ~TriadSimulator();
  // The axes' inputs point into the simulator: it stays where it was built.
  TriadSimulator(const TriadSimulator&) = delete;
  TriadSimulator& operator=(const TriadSimulator&) = delete;

  const TriadSimulationConfig& config() const { return config_; }
  const TriadMotion& motion() const { return motion_; }
  /// Simulated duration of the whole session, s.
  double duration() const { return config_.duration(); }
  /// Simulated time reached, s from the start.
  double elapsed() const { return axes_[0]->elapsed(); }
  bool done() const { return axes_[0]->done(); }

  /// The next output sample; false once the session is complete.
  bool next(TriadSample* out);

  /// What the table controller has logged so far (records made, lost, glitched).
  const TurntableLogCounters& turntableLogCounters() const { return logger_.counters(); }

 private:
  class AxisInput;
  void logTurntable(double t_center, Nanoseconds stamp, const TriadBodyState& state, TriadSample* out);
  void logFixture(double t_center, const TriadBodyState& state, TriadSample* out);
  /// The accelerometer's record over the sample [t_start, t_end] at the centre's state.
  void measureAcceleration(double t_start, double t_end, const TriadBodyState& state, TriadSample* out);

  TriadSimulationConfig config_;
  TriadMotion motion_;
  std::array<std::unique_ptr<AxisInput>, 3> inputs_;
  std::array<std::unique_ptr<GyroSimulator>, 3> axes_;
  TurntableLogger logger_;
  GaussianNoise accelerometer_noise_;
  Eigen::Matrix3d accelerometer_misalignment_;  // Rot(rho)^T
  std::uint64_t next_log_ = 0;                  // index of the next record at the table's log rate
  std::vector<Eigen::Quaterniond> nominal_;
  bool fixture_logged_once_ = false;
  double last_fixture_log_ = 0.0;  // s
  FixtureState last_fixture_;
};

}  // namespace core
}  // namespace hrg_gyro
