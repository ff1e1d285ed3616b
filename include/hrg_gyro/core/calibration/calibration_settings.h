// Settings of a calibration run and its quality gates. The keys are the calibrator node's private
// parameters (and `hrg_bag calibrate --config`), parsed by one function for both.
#pragma once

#include <cmath>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "hrg_gyro/core/common/stamp_timeline.h"
#include "hrg_gyro/core/common/yaml_field.h"
#include "hrg_gyro/core/estimation/plateau_detector.h"
#include "hrg_gyro/core/model/calibration_method_kind.h"
#include "hrg_gyro/core/model/frequency_interpolator.h"
#include "hrg_gyro/core/resonator/control_loops.h"
#include "hrg_gyro/core/resonator/drive_chain.h"
#include "hrg_gyro/core/resonator/shell_parameters.h"

namespace hrg_gyro {
namespace core {

/// Acceptance thresholds. A result that fails any is refused and nothing is written.
struct QualityLimits {
  double min_coverage = 0.95;           ///< fraction of theta bins with data, per plateau group
  double min_rate_separation = 0.01;    ///< rad/s between the two dual-rate groups
  double max_rate_noise = 1e-3;         ///< std of the reported table rate / |rate| within a group
  double max_table_error = 2e-5;        ///< dual-rate: K-harmonic error from table errors (upper estimate) / |K0|
  std::uint64_t min_samples = 1000;     ///< wave samples used
  double max_condition = 1e4;           ///< of the harmonic design matrix
  double max_relative_residual = 1e-3;  ///< rms of binned K about the fit / |K0|
  double max_k0_change = 0.2;           ///< |K0 - K0 prior| / |K0 prior|
  double max_harmonic_std = 1e-5;       ///< largest standard error of a K harmonic / |K0|
  int min_steps = 8;                    ///< step method: steps used
  double min_dwell_time = 5.0;          ///< s of static data (step and constant-rate methods)
  std::uint64_t min_pairs = 24;         ///< correction-matrix method: generator samples
  double max_p_condition = 1e3;         ///< correction-matrix method
  /// dual-rate: a session cannot tell a bias trend from K0 (refused, the plateau order named) when
  /// fitting the trend multiplies K0's standard error by more than max_trend_inflation and leaves it
  /// above max_trend_k0_std of |K0|
  double max_trend_inflation = 3.0;
  double max_trend_k0_std = 2e-6;
};

/// The thermal method (K and D as splines over the resonator frequency, thermal_method.h).
struct ThermalSettings {
  /// Hz, strictly increasing; empty: node_count nodes spread evenly over the frequencies seen.
  std::vector<double> frequency_nodes;
  int node_count = 3;
  Interpolation interpolation = Interpolation::kNaturalCubicSpline;
  double slice_width = 0.5;  ///< Hz: the data are theta-binned separately per frequency slice
  int max_slices = 512;      ///< bound on the slices kept (memory): data in further slices are dropped
  std::size_t nodeCount() const { return frequency_nodes.empty() ? node_count : frequency_nodes.size(); }
};

/// The table's clock (table_clock section): its stamps may come from another computer than the
/// gyro's, offset and with jitter. See table_stamp_regulariser.h and table_clock_offset.h.
struct TableClockSettings {
  double offset = 0.0;       ///< s, a known offset of the table's stamps, subtracted before anything
  bool regularise = true;    ///< a fixed-rate log's stamps put on the line through them
  double window = 600.0;     ///< s of records the line is fitted over
  double max_jitter = 5e-3;  ///< s: a log whose stamps scatter more about their line is not fixed-rate
  double max_offset = 0.5;   ///< s: an estimated offset beyond this (3 sigma included) is refused
};

/// The gyro's resonator, loops and drive, as far as they set the drift the loops' lag adds to a
/// precessed wave (precessionLagDrift in resonator/first_order_model.h): from the gyro's maker, or
/// a simulated gyro's scenario (its dynamics section's shell, loops and drive).
struct FieldResonator {
  ShellParameters shell;
  LoopSettings loops;
  DriveChainErrors drive;
};

/// The field method (field_method.h): a still gyro whose precession loop turns the wave both ways.
/// `rate`, `turns`, `directions` and `rest` plan the virtual rotation the live calibrator commands
/// (fieldCommandPlan); the rest are the estimator's orders and the method's own gates.
struct FieldSettings {
  std::vector<int> gain_orders{2, 4};  ///< harmonic orders of the virtual rate's gain G_v(theta)
  /// rad/s (electrical), |commanded virtual rate|, in [kMinRate, kMaxPrecessionRate]. Faster, the loops' lag
  /// adds more drift (as the rate squared and faster): see `resonator` and the loop_lag gate.
  double rate = 0.2;
  double turns = 2.0;                         ///< full turns of theta (2 pi) per segment, at most kMaxTurns
  std::vector<int> directions{1, -1, -1, 1};  ///< the segments' signs, in order (+ - - +: a linear bias trend cancels)
  double rest = 5.0;                          ///< s at rest (commanded 0) before the first segment, at most kMaxRest
  /// The gyro's resonator where known: the drift the loops' lag adds at the commanded rate is then
  /// predicted, noted and gated (loop_lag); empty ('unknown'): it is not predicted, a note says so.
  std::optional<FieldResonator> resonator;
  /// rad/s, the Earth's rate about the sensitive axis where the gyro stands (Omega_E . u, from the
  /// vehicle's attitude and latitude), taken off with K to leave D0; NaN ('vertical'): the vertical
  /// component at the prior's latitude, for an axis that points up
  double axis_earth_rate = NAN;
  double min_turns = 1.0;  ///< gate: full turns of theta per direction
  /// gate (stillness): the scatter of the data about the fit over what the white wave-angle noise
  /// predicts, on D's harmonics (not D0): a case that moves (or a rate noise) raises it
  double max_excess_scatter = 3.0;
  double max_gain_error = 0.05;  ///< gate: |G_v0 - 1|, a loop that does not realise the command
  double max_drift_std = 1e-7;   ///< gate: rad/s, the largest standard error of a D term

  /// Bounds of the plan's keys (each refused by name beyond them); the whole plan is bounded by
  /// kMaxFieldPlanDuration (below).
  static constexpr double kMinRate = 0.01;  ///< rad/s (the largest: kMaxPrecessionRate, control_loops.h)
  static constexpr double kMaxTurns = 100.0;
  static constexpr double kMaxRest = 600.0;  ///< s
  static constexpr std::size_t kMaxDirections = 16;
};

struct CalibrationSettings {
  CalibrationMethodKind method = CalibrationMethodKind::kDualRate;
  std::vector<int> scale_factor_orders{2, 4, 6, 8};
  std::vector<int> drift_orders{2, 4};
  /// dual-rate: degree of the bias's polynomial in time fitted with K and D (0: constant, 1: linear
  /// trend, 2: quadratic)
  int bias_trend_order = 1;
  int bins = 128;                  ///< theta bins over [0, pi)
  double window = 2.0;             ///< s, longest averaging window tau
  double window_span = 0.06;       ///< rad, most wave angle a window may sweep (shortens tau at high rates)
  double group_tolerance = 1e-3;   ///< rad/s: plateaus closer than this in rate form one group
  double auto_finish_idle = 20.0;  ///< s at rest after the data are complete -> finish (<= 0: never)
  /// The stamp rule of every stream of the run (common/stamp_timeline.h): a record further back
  /// than backward_reset, or further ahead than forward_jump (of its stream and of the others), is
  /// a glitch, dropped; jump_persist records in a row past one jump make it real: going back (bag
  /// loop) the run restarts, going ahead it goes on across the gap.
  double backward_reset = 0.5;  ///< s
  double forward_jump = 1.0;    ///< s
  int jump_persist = 5;         ///< records (the settings key backward_persist is its former name)
  StampRule stampRule() const;
  PlateauSettings plateau;
  QualityLimits gates;
  ThermalSettings thermal;
  TableClockSettings table_clock;
  FieldSettings field;

  /// Parses the calibrator settings map. Throws ConfigError naming the key.
  static CalibrationSettings parse(const YamlField& root, const std::vector<std::string>& extra_keys = {});
  /// Every key parse() reads, nested ones as "section/key" (the calibrator's parameter template lists them all).
  static std::vector<std::string> keyPaths();
  /// Former names of keys that parse() still reads (backward_persist), not in keyPaths().
  static std::vector<std::string> formerKeyPaths();
};

/// The longest field plan, s: a day of a still vehicle.
constexpr double kMaxFieldPlanDuration = 86400.0;
/// s of one segment of the field plan at the settings' rate (field_command_plan.h: the plan).
double fieldSegmentDuration(const CalibrationSettings& settings);
/// s from the plan's start to its last command (rest + one segment per direction); may be infinite.
double fieldPlanDuration(const CalibrationSettings& settings);
/// "the plan lasts ...: ..." when it is longer than kMaxFieldPlanDuration (or not finite), else "".
std::string fieldPlanLengthProblem(const CalibrationSettings& settings);

}  // namespace core
}  // namespace hrg_gyro
