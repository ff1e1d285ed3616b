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
#include "hrg_gyro/core/processing/imu_increment_converter.h"

namespace hrg_gyro {
namespace core {

enum class AlignmentMode { kStatic, kIndexed, kSweep };
/// "static", "indexed", "sweep".
const char* toString(AlignmentMode mode);
/// Throws ConfigError naming `key` for any other text.
AlignmentMode parseAlignmentMode(const std::string& text, const std::string& key = "mode");

/// One gyro axis's noise and what its calibration left, in body units. A term that is NaN was not
/// given: nothing claims a precision nobody measured, so the gyrocompass refuses to start until each
/// is set, read from an Allan file, or (the residual bias) taken from a calibrated triad file.
struct GyroNoiseModel {
  double angle_white_noise = -1.0;  ///< rad per sample (Q of the Allan deviation); negative: measured
  double angle_random_walk = NAN;   ///< N, rad/sqrt(s)
  double rate_random_walk = NAN;    ///< K, rad/s/sqrt(s): the bias that wanders at random
  /// rad/s, 1 sigma: the bias the calibration left (for a triad, its file's bias_std), constant over
  /// the window: a floor of the static heading, cancelled by indexing.
  double residual_bias = NAN;
  /// rad/s, 1 sigma: the rms over the wave angle of the residual D(theta) - D0, divided by |K0| (body
  /// rate). A resting wave turns it into a bias of that size (static); a sweep averages it out.
  double residual_drift_harmonics = NAN;
  /// rad, the quantum of the angle an IMU's increments are counted in (0.1 arcsec counts: 4.848e-7),
  /// 0 none: its rounding's white angle noise q^2/12, which a window's measurement cannot see, is added
  /// to the measured white noise and floors a given one. An HRG's angle is not quantised: 0.
  double angle_quantum = 0.0;
  /// Throws ConfigError naming `prefix` + the field (a term not given passes: NaN).
  void validate(const std::string& prefix = "noise/") const;
  /// Throws ConfigError naming the first term not given, and where to get it.
  void requireComplete(const std::string& prefix = "noise/") const;
};

/// Where each noise term came from ("settings", "allan_file PATH", "triad_file bias_std", "measured
/// from the window"): the diagnostics and the result say it.
struct NoiseSources {
  std::string angle_white_noise = "measured from the window";
  std::string angle_random_walk = "settings", rate_random_walk = "settings";
  std::string residual_bias = "settings", residual_drift_harmonics = "settings";
  /// One line, term by term.
  std::string summary() const;
};

/// The readings an Allan deviation identified (Q as the white angle noise at its sample period, N,
/// K) in place of `base`'s; the rest of `base` kept. `sources` (optional) records `origin` for each.
GyroNoiseModel noiseFromAllan(const AllanResult& allan, const GyroNoiseModel& base, NoiseSources* sources = nullptr,
                              const std::string& origin = "allan_file");

enum class LevelSource { kAccelerometer, kDeclared };

struct LevelSettings {
  LevelSource source = LevelSource::kAccelerometer;
  /// Declared level of the body (static, sweep) or of the indexer's zero frame (indexed), rad.
  double roll = 0.0, pitch = 0.0;
  /// rad, 1 sigma of the declared level (0: exact); NaN: not given (required with a declared level).
  double roll_sigma = NAN, pitch_sigma = NAN;
  /// The accelerometer's mounting: v_body = accelerometer_to_body v_accelerometer.
  Eigen::Quaterniond accelerometer_to_body = Eigen::Quaterniond::Identity();
  /// m/s^2, 1 sigma per axis of the bias its calibration left; NaN: not given (required with an
  /// accelerometer).
  double accelerometer_bias_sigma = NAN;
  /// rad, 1 sigma per axis of the mounting's error (how well accelerometer_to_body is known); NaN:
  /// not given (required with an accelerometer). It tips the level as a bias of g times it does.
  double accelerometer_mounting_sigma = NAN;
  /// Largest | |f| / g - 1 | of the mean specific force (a wrong unit or a moving base).
  double max_gravity_error = 0.02;
  void validate() const;
  /// Throws ConfigError naming the sigma the level source needs and that was not given.
  void requireComplete() const;
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
  /// s: blocks whose mean rates judge stillness within a rest, and over which the residuals are
  /// averaged for the low-frequency stillness (a sway slower than the blocks)
  double block = 2.0;
  double max_motion = 1e-4;  ///< rad/s: largest departure of a block's mean rate from the others' in a rest
  /// Largest rms residual over the noise model's prediction, per point and per block mean. Still
  /// windows read 1.00 to 1.03 (every mode, 300 simulated windows).
  double max_scatter = 1.5;
  /// The still-base fit's steps of the base (a lean, a knock: a rotation that stays): a step whose
  /// chi-square (3 degrees of freedom for the triad) exceeds `step_threshold` is carried: the window is
  /// cut there, `step_guard` s each side left out, the rests on either side fitted together with the
  /// rotation between them measured by the gyros. At most `max_steps`, at most `max_excluded` of the
  /// window left out; beyond either the base is not still (the tracking estimator, or a refusal).
  double step_threshold = 40.0;
  double step_guard = 0.5;
  int max_steps = 12;
  double max_excluded = 0.3;
  /// The block means' test (a slow sway): how often a still window is refused by it; its limit is the
  /// chi-square quantile for the window's number of blocks.
  double block_false_alarm = 1e-4;
  void validate() const;
};

/// Which estimator answers. kAuto: the still-base fit where the base is still (the most precise),
/// the tracking estimator (the gyros track the body, gravity followed in the inertial frame; needs an
/// accelerometer and the triad) where the base sways or moves in a way the still fit cannot carry, or
/// where the two disagree beyond their noise.
enum class EstimatorChoice { kAuto, kStillBase, kTracking };
const char* toString(EstimatorChoice choice);

/// The gyros' stream: the HRG triad's body samples (TriadOutput), or any IMU's sensor_msgs/Imu turned
/// back into increments (processing/imu_increment_converter.h), its accelerometer the level's.
enum class GyroInput { kTriad, kImu };
const char* toString(GyroInput input);

/// The IMU input's keys beside the converter's: where the level's specific force comes from, and the
/// frame the results and the hold are reported in.
struct ImuInput {
  ImuInputSettings converter;
  /// level/source accelerometer: the IMU's own linear_acceleration (true), or accel/data_raw (false).
  bool accelerometer = true;
  /// frame_id of the results and of the held imu/data; "": the IMU messages' own frame_id.
  std::string body_frame;
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
  /// Each check against the Earth (earth_checks.h: the measured Earth rate's length, its vertical part
  /// and its angle to the measured up) refuses beyond this many of its standard errors.
  double max_earth_sigmas = 5.0;
  /// The tracking estimator replaces the still-base fit when their headings differ by more than this
  /// many standard errors of the difference (their noise; the biases they share cancel).
  double max_estimator_sigmas = 4.0;
  EstimatorChoice estimator = EstimatorChoice::kAuto;
  double max_condition = 1e8;  ///< of the fit (a design that cannot separate the parameters)
  GyroNoiseModel noise;
  NoiseSources noise_sources;  ///< set by parse(); a caller that fills `noise` itself keeps "settings"
  std::string allan_file;      ///< the Allan readings file `noise` was read from (its path as opened), "" none
  /// s, that file's sample period: its Q is per sample of that rate, so a window whose samples are
  /// spaced otherwise (by more than 2 %) is refused (gate noise); 0: no file.
  double allan_tau0 = 0.0;
  LevelSettings level;
  IndexerSettings indexer;
  SweepSettings sweep;
  MotionSettings motion;
  GyroInput gyro_input = GyroInput::kTriad;
  ImuInput imu;  ///< gyro_input imu
  /// Throws ConfigError naming the key.
  void validate() const;
  /// validate(), and every noise term and level sigma given (the gyrocompass's start).
  void requireComplete() const;

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
