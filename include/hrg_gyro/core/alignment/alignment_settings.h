// What an alignment from the Earth's rate (gyrocompassing) is told: the mode, the site, the window,
// the gyros' noise and what their calibration left, the gravity reference, the indexer, the sweep, and
// the gates. Every value is checked by validate(), which names the key (the gyrocompass node's private
// parameter of the same name) in a ConfigError.
//
// The modes (what each can resolve):
//   static  the triad at rest, levelled by gravity: the Earth's rate seen by the three body axes.
//           The triad's residual bias, and its D(theta) at the angles where the waves rest, enter the
//           heading in full, divided by the horizontal Earth rate: a floor no window length lowers.
//   indexed the triad, or one gyro with a horizontal sensitive axis, on an indexer or rate table whose
//           angle is read: two positions 180 deg apart, four positions, or continuous rotation. The
//           gyro's own bias (and its D at a resting wave) cancels. One gyro at two positions senses
//           one horizontal component only: the heading is then ambiguous (two mirror solutions) and
//           refused; four positions, continuous rotation, or the triad's two horizontal axes resolve it.
//   sweep   the triad at rest while the precession loop turns each axis's wave through whole turns,
//           +rate then -rate: D(theta)'s harmonics average out instead of entering the heading, and
//           the commanded virtual rate, executed with an unknown gain G_v near 1, is fitted out.
//
// The noise model (per gyro axis, in body rate units: rad, rad/s) comes from the settings, or from the
// Allan deviation the package computes (`noise/allan_file`: the readings `hrg_bag allan --yaml` wrote,
// whose identified Q, N and K replace the keys; noiseFromAllan); the white angle noise is measured
// from the window itself unless given.
//
// As YAML (the gyrocompass node's private parameters, `hrg_bag align --settings`): the fields below
// by name, each section a map (`level: {source: declared, roll: 0.0, ...}`), `mode` and
// `level/source` as text, rotations as {roll, pitch, yaw} in rad (R = Rz(yaw) Ry(pitch) Rx(roll)),
// `indexer/gyro_axis` as [x, y, z]; an absent key keeps its default. No ROS.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>
#include <string>
#include <vector>

#include "hrg_gyro/core/common/yaml_field.h"
#include "hrg_gyro/core/estimation/allan_deviation.h"

namespace hrg_gyro {
namespace core {

enum class AlignmentMode { kStatic, kIndexed, kSweep };
/// "static", "indexed", "sweep".
const char* toString(AlignmentMode mode);
/// Throws ConfigError naming `key` for any other text.
AlignmentMode parseAlignmentMode(const std::string& text, const std::string& key = "mode");

/// One gyro axis's noise and what its calibration left, in body units.
struct GyroNoiseModel {
  double angle_white_noise = -1.0;  ///< rad per sample (Q of the Allan deviation); negative: measured
  double angle_random_walk = 0.0;   ///< N, rad/sqrt(s)
  double rate_random_walk = 0.0;    ///< K, rad/s/sqrt(s): the bias that wanders at random
  /// rad/s, 1 sigma: the bias the calibration left (for a triad, its file's bias_std), constant over
  /// the window: a floor of the static heading, cancelled by indexing.
  double residual_bias = 0.0;
  /// rad/s, 1 sigma: the rms over the wave angle of the residual D(theta) - D0, divided by |K0| (body
  /// rate). A resting wave turns it into a bias of that size (static); a sweep averages it out.
  double residual_drift_harmonics = 0.0;
  /// Throws ConfigError naming `prefix` + the field.
  void validate(const std::string& prefix = "noise/") const;
};

/// The readings an Allan deviation identified (Q as the white angle noise at its sample period, N,
/// K) in place of `base`'s; the rest of `base` kept.
GyroNoiseModel noiseFromAllan(const AllanResult& allan, const GyroNoiseModel& base);

enum class LevelSource { kAccelerometer, kDeclared };

struct LevelSettings {
  LevelSource source = LevelSource::kAccelerometer;
  /// Declared level of the body (static, sweep) or of the indexer's zero frame (indexed), rad.
  double roll = 0.0, pitch = 0.0;
  double roll_sigma = 0.0, pitch_sigma = 0.0;  ///< rad, 1 sigma (0: exact)
  /// The accelerometer's mounting: v_body = accelerometer_to_body v_accelerometer.
  Eigen::Quaterniond accelerometer_to_body = Eigen::Quaterniond::Identity();
  /// m/s^2, 1 sigma per axis of the bias its calibration left (its mounting's error can be folded in
  /// as g times the angle).
  double accelerometer_bias_sigma = 0.0;
  /// Largest | |f| / g - 1 | of the mean specific force (a wrong unit or a moving base).
  double max_gravity_error = 0.02;
  void validate() const;
};

struct IndexerSettings {
  /// false: the positions mode (only samples at rest on the indexer count, each rest its own
  /// segment); true: continuous rotation (every sample, at the indexer angle of its stamps).
  bool continuous = false;
  /// The body (the triad's frame) on the indexer's platform: v_platform = body_to_platform v_body.
  Eigen::Matrix3d body_to_platform = Eigen::Matrix3d::Identity();
  /// One gyro: its sensitive axis in the platform frame (unit; horizontal for north-finding).
  Eigen::Vector3d gyro_axis = Eigen::Vector3d::UnitX();
  double rest_rate = 1e-3;           ///< rad/s: the indexer is at rest below this rate
  double settle = 1.0;               ///< s after the indexer comes to rest before samples count
  double position_tolerance = 1e-3;  ///< rad: a rest whose angle wanders further is refused
  double max_record_gap = 0.5;       ///< s: samples between records further apart are not covered
  /// rad, 1 sigma: each position's (or, continuous, the zero mark's) angle error, for the budget.
  double angle_sigma = 0.0;
  void validate() const;
};

struct SweepSettings {
  double settle = 2.0;  ///< s after each change of the commanded rate not used (the loops settle)
  /// Harmonic orders of the realised virtual-rate gain G_v(theta) (and of the processor's K(theta)
  /// acting on the commanded rate) fitted out: their angle sin(k psi)/k, cos(k psi)/k.
  std::vector<int> gain_orders{2, 4};
  double min_turns = 1.0;  ///< whole turns of the commanded angle required each way
  void validate() const;
};

struct MotionSettings {
  double block = 2.0;        ///< s: blocks whose mean rates judge stillness within a segment
  double max_motion = 1e-4;  ///< rad/s: largest departure of a block's mean rate from the others'
  /// Largest rms residual over the noise model's prediction. Still windows read 1.00 to 1.03 (every
  /// mode, 300 simulated windows); a 0.05 Hz sway of 5e-5 rad reads 2.7 in 20 s and turns the heading
  /// by 2 deg.
  double max_scatter = 1.5;
  void validate() const;
};

struct AlignmentSettings {
  AlignmentMode mode = AlignmentMode::kStatic;
  double latitude = NAN;            ///< rad, geodetic, north positive (required)
  double max_latitude = 1.3962634;  ///< rad (80 deg): refused above, Omega cos(lat) too small
  double duration = 120.0;          ///< s of gyro stamps in the window
  bool single_gyro = false;         ///< indexed: one gyro (addAxis) instead of the triad
  /// Largest | h_measured / h - 1 | of the horizontal rate against the Earth's (a bias far beyond the
  /// calibration's, a wrong latitude, a turning base), beyond 4 of its sigmas.
  double max_earth_rate_error = 0.25;
  double max_condition = 1e8;  ///< of the fit (a design that cannot separate the parameters)
  GyroNoiseModel noise;
  LevelSettings level;
  IndexerSettings indexer;
  SweepSettings sweep;
  MotionSettings motion;
  /// Throws ConfigError naming the key.
  void validate() const;

  /// Reads the settings map (the top level of a settings file or of the node's parameters) and
  /// validates it. Unknown keys are refused by name; `extra_keys` are also allowed at the top level,
  /// unread (someone else's). A relative `noise/allan_file` is read from `base_directory` (the settings
  /// file's); without one it must be absolute. Throws ConfigError naming the key as the file writes it
  /// ("level.roll").
  static AlignmentSettings parse(const YamlField& root, const std::vector<std::string>& extra_keys = {},
                                 const std::string& base_directory = "");
  /// A settings file: the settings at its top level, beside them (unread) the gyrocompass node's own
  /// keys (nodeKeys()), so the node's parameter file config/gyrocompass.yaml is one too. Throws
  /// ConfigError (an unreadable file, a YAML syntax error with its line, a bad key).
  static AlignmentSettings load(const std::string& path);
  /// The gyrocompass node's keys that are not the alignment's (align_at_startup, triad_file, ...).
  static const std::vector<std::string>& nodeKeys();
  /// Every key parse() reads, nested ones as "section/key".
  static std::vector<std::string> keyPaths();
};

}  // namespace core
}  // namespace hrg_gyro
