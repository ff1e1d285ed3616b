// A triad scenario: three HRG axes in one fixture on a single-axis rate table, the fixture clamped in
// a sequence of positions (the standard multi-position calibration), the table turning through each
// position's profile and standing still while the fixture is moved to the next. One YAML file: `seed`,
// `start_time` and a `triad` section (docs/simulation.md, "A triad on a rate table"; every key below
// is refused by name when wrong, and an unknown key too).
//
// Frames (REP-103: right-handed, rad, counter-clockwise positive):
//   body         the fixture's frame `frame_id`; the axes' sensitive directions are given in it.
//   table        turns with the platter: z along the table's axis of rotation (up), x at the platter's
//                zero mark. It is the table-zero frame turned by the table angle phi about z.
//   table zero   the table frame at phi = 0, Earth-fixed: its x axis points at `azimuth`, measured
//                from North towards East; z up. The Earth's rate (East, North, Up) =
//                (0, W cos(lat), W sin(lat)) there is (W cos(lat) cos(az), W cos(lat) sin(az), W sin(lat)).
//
// The axes: axis i senses r_i = A_i . omega_body, A_i the row i of A (TriadParameters::bodyToAxis,
// A = M^-1): A_ii = 1 + scale_i, and `misalignment: [a_ij, a_ik]` the two off-diagonal entries of
// the row, j < k the other two body axes in x, y, z order (x: [A_xy, A_xz]; y: [A_yx, A_yz]; z:
// [A_zx, A_zy]), the tilt of axis i towards body axis j, rad. Not normalised: A is what the triad
// file holds. Axis i then integrates d theta_i/dt = K_i(theta_i) r_i + D_i(theta_i) through its own
// pickoffs (today's single-axis chain, GyroSimulator). An axis's `dynamics` section is a single gyro
// scenario's (dynamics_config.h): with model: averaged the axis runs the resonator with its loops,
// sensing r_i, and its precession loop follows the section's `commands` (whole turns of its wave while
// the triad stands still: the gyrocompass's sweep mode).
//
// The positions: `up: "+x"` (one of +-x, +-y, +-z) puts that body axis along the table's axis, up
// (+) or down (-), and the body axis after it in the cyclic order x -> y -> z -> x along the
// platter's x axis (so "+z" is the identity and "-z" a half turn about x); `body_to_table: {roll,
// pitch, yaw}` gives any other orientation, R = Rz(yaw) Ry(pitch) Rx(roll). The fixture's mounting
// error of a position, `error: [rx, ry, rz]` (rad), is a small rotation vector in the platter's frame
// applied after the nominal one: body_to_platter = Exp(error) R. Before each position but the first,
// the fixture is unclamped for `move` s: the table stands still and the body turns, about the one
// fixed axis that takes it there by the smallest angle, from the previous (true) orientation to this
// one, its angle following s(u) = u - sin(2 pi u) / (2 pi) of the elapsed fraction u (at rest at
// both ends).
//
// The table may wobble: its platter's top is tilted by `wobble.amplitude` rad, the platter's normal
// leaning towards the platter direction `wobble.direction` (rad from the platter's x axis), a tilt
// that turns with the platter (a coning of the platter's normal about the table's axis):
// body_to_table = W body_to_platter, W that tilt. For the body it is one more small rotation of the
// fixture, the same in the platter's frame in every position.
//
// The body's true orientation in ENU (REP-103, body -> ENU): Rz(pi/2 - azimuth) Rz(phi) body_to_table,
// the table-zero frame's x axis at yaw pi/2 - azimuth (counter-clockwise from East). The ground may
// move (`base_motion`, off by default; base_motion.h): the whole table stands on a base turned by
// D(t), so the attitude becomes D(t) times that. An accelerometer (`accelerometer`, off by default)
// may ride on the fixture at the table's axis (no lever arm): it measures the specific force, gravity's
// (REP-145: +g up) plus the base's vibration, in its frame, with its own errors (scale, misalignment,
// axis signs, convention, bias, noise, quantum: the order in triad_simulator.h), at the axes' stamps.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "hrg_gyro/core/common/yaml_field.h"
#include "hrg_gyro/core/model/triad_parameters.h"
#include "hrg_gyro/core/simulation/base_motion.h"
#include "hrg_gyro/core/simulation/simulation_config.h"

namespace hrg_gyro {
namespace core {

struct TriadAxisConfig {
  std::string name;  ///< the axis's namespace in topics (x/channels) and launch files
  ResonatorConfig resonator;
  PickoffDefects pickoff;
  DeliveryConfig channels;               ///< lost channel samples of this axis (default: none)
  std::array<double, 2> misalignment{};  ///< a_ij, a_ik: towards the other body axes in x, y, z order, rad
  double scale = 0.0;                    ///< residual scale s_i: A_ii = 1 + s_i
  /// How its wave moves (dynamics_config.h): the given K and D by default, or the averaged resonator
  /// with its loops and a schedule of precession commands (`dynamics/commands`).
  DynamicsConfig dynamics;
};

/// The platter's top tilted against the table's axis by a tilt that turns with it.
struct TableWobbleConfig {
  double amplitude = 0.0;  ///< rad
  double direction = 0.0;  ///< rad: the platter direction (from its x axis) the platter's normal leans towards
  /// W: vectors of the platter's frame into the table frame (identity without wobble).
  Eigen::Matrix3d platterToTable() const;
};

/// An accelerometer on the fixture (`triad/accelerometer`): what a gravity reference for the level sees.
struct TriadAccelerometerConfig {
  bool enabled = false;
  std::string frame_id = "accel_link";
  Eigen::Vector3d bias = Eigen::Vector3d::Zero();  ///< m/s^2, in its own frame
  double noise = 0.0;                              ///< m/s^2, white, 1 sigma per sample
  /// v_body = accelerometer_to_body v_accelerometer (`mounting: {roll, pitch, yaw}`).
  Eigen::Matrix3d accelerometer_to_body = Eigen::Matrix3d::Identity();
  // Its own errors (the defaults: none). What users get wrong too: a reversed axis, the sign convention.
  Eigen::Vector3d scale = Eigen::Vector3d::Zero();  ///< s_j: axis j reads (1 + s_j) of its component
  /// rad, rho: its axes turned by Rot(rho) from the mounted ones, so it reads Rot(rho)^T f.
  Eigen::Vector3d misalignment = Eigen::Vector3d::Zero();
  Eigen::Vector3d axis_signs = Eigen::Vector3d::Ones();  ///< each +1 or -1 (-1: that axis reversed)
  /// kSpecificForce: +g up at rest (REP-145); kGravity: it reports minus the specific force (-g up).
  enum class Convention { kSpecificForce, kGravity } convention = Convention::kSpecificForce;
  double quantum = 0.0;  ///< m/s^2: each record rounded to a multiple of it (0: not quantised)
};

struct TriadTurntableConfig {
  double latitude = 0.0;      ///< rad, geodetic
  double azimuth = 0.0;       ///< rad: the platter's x axis at table angle 0, from North towards East
  double acceleration = 0.5;  ///< rad/s^2, every rate change of every position's profile
  TableRippleConfig ripple;   ///< drive speed ripple (default: none)
  TurntableLogConfig log;     ///< what the table controller logs (default: the exact state, with every sample)
  TableWobbleConfig wobble;   ///< default: none

  /// The Earth's rate in the table-zero frame, rad/s.
  Eigen::Vector3d earthRateInTableZero() const;
  /// The table-zero frame in ENU: Rz(pi/2 - azimuth).
  Eigen::Matrix3d tableZeroToEnu() const;
};

struct FixturePositionConfig {
  std::string name;
  Eigen::Matrix3d nominal = Eigen::Matrix3d::Identity();  ///< body_to_table as planned (FixturePosition)
  Eigen::Vector3d error = Eigen::Vector3d::Zero();        ///< rad, rotation vector in the platter's frame
  bool error_given = false;  ///< false: `error` is drawn (TriadSimulationConfig::fixture_error_std)
  TurntableProfile profile;  ///< the table's motion in this position
  double move = 0.0;         ///< s unclamped before it (0: the first position)
  // The session's times of this position, s from the scenario start (set by the parser).
  double move_start = 0.0;  ///< the fixture is unclamped (= start for the first position)
  double start = 0.0;       ///< clamped in this position
  double end = 0.0;         ///< its profile is over

  /// The true body_to_platter: Exp(error) nominal.
  Eigen::Matrix3d bodyToPlatter() const;
};

struct TriadSimulationConfig {
  std::uint64_t seed = 1;
  double start_time = 1.0;  ///< s: stamp of the first instant (ROS treats time 0 as unset)
  std::string frame_id = "imu_link";
  std::array<TriadAxisConfig, 3> axes;  ///< in body-axis order x, y, z
  TriadTurntableConfig turntable;
  std::vector<FixturePositionConfig> positions;
  double fixture_error_std = 0.0;  ///< rad: the errors of the positions that give none, drawn
  TriadAccelerometerConfig accelerometer;
  /// The ground under the table (`triad.base_motion`, base_motion.h): still by default.
  BaseMotionConfig base_motion;
  /// The whole session's table motion: each position's profile in turn, the table at rest during the
  /// moves, ripple included; labels "<position>/<segment>" and "<position>/move" (set by the parser).
  TurntableProfile table_profile;

  /// The axes share their output stamps: one resonator period and output period for all.
  double outputPeriod() const { return axes[0].resonator.periods_per_output / axes[0].resonator.frequency; }
  /// Simulated duration, s.
  double duration() const { return table_profile.duration(); }
  /// Sets the seed and draws again the fixture errors that are not given (a --seed option).
  void setSeed(std::uint64_t new_seed);
  /// A: row i = axis i's sensitive direction in the body frame times (1 + scale_i).
  Eigen::Matrix3d bodyToAxis() const;
  /// What a perfect calibration on this fixture finds: M = A^-1, no body bias (each axis's own D is
  /// its parameter file's), the axes' names and the body frame.
  TriadParameters injectedTriad() const;
  /// Axis i as a single-axis scenario: its gyro and channel losses on the session's table profile, its
  /// own seed. What GyroSimulator runs for it (with the axis-rate input); computeEffectiveModel() of
  /// it is the axis's injected K and D.
  SimulationConfig axisScenario(int axis) const;

  /// Parses a triad scenario (top-level keys `seed`, `start_time`, `triad`, and `extra_keys`, the
  /// ROS-only parameters of driver_sim). Throws ConfigError naming the key.
  static TriadSimulationConfig parse(const YamlField& root, const std::vector<std::string>& extra_keys = {});
  /// Reads and parses a triad scenario file (loadScenarioDocument's checks).
  static TriadSimulationConfig load(const std::string& path, const std::vector<std::string>& extra_keys = {});
};

/// True for a triad scenario (a document with a `triad` section): the ROS front ends pick the
/// simulator by it.
bool isTriadScenario(const YAML::Node& root);

/// Exp of a rotation vector (axis times angle, rad): the rotation matrix.
Eigen::Matrix3d rotationFromVector(const Eigen::Vector3d& rotation);
/// Rz(yaw) Ry(pitch) Rx(roll).
Eigen::Matrix3d rotationFromRollPitchYaw(double roll, double pitch, double yaw);
/// The body_to_table of an `up` position ("+x", "-x", "+y", "-y", "+z", "-z"); false for anything else.
bool rotationForUp(const std::string& up, Eigen::Matrix3d* body_to_table);

}  // namespace core
}  // namespace hrg_gyro
