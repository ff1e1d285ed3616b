// What a calibration run produced: the estimates with their uncertainties, the data summary, each
// quality gate, and the parameter set to write when accepted. Also its YAML report form, read by
// scripts/plot_calibration.py.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "hrg_gyro/core/estimation/binned_rate_fit.h"
#include "hrg_gyro/core/estimation/defect_diagnosis.h"
#include "hrg_gyro/core/estimation/harmonic_fit.h"
#include "hrg_gyro/core/estimation/increment_fit.h"
#include "hrg_gyro/core/estimation/table_clock_offset.h"
#include "hrg_gyro/core/estimation/table_stamp_regulariser.h"
#include "hrg_gyro/core/model/correction_matrix.h"
#include "hrg_gyro/core/model/gyro_parameters.h"

namespace YAML {
class Emitter;
}

namespace hrg_gyro {
namespace core {

/// Records of the rotation's stream (turntable states, or in a field run precession states) dropped
/// before the plateau detector, by reason.
struct RotationRecordRejects {
  std::uint64_t bad_rate = 0;      ///< non-finite, or |rate| above plateau/max_rate
  std::uint64_t bad_angle = 0;     ///< non-finite, or a step from the last good angle beyond max_rate
  std::uint64_t bad_stamp = 0;     ///< zero or negative stamp
  std::uint64_t duplicate = 0;     ///< the stamp of the last good record
  std::uint64_t out_of_order = 0;  ///< behind the last good stamp by at most backward_reset
  std::uint64_t stamp_jump = 0;    ///< further back or ahead: a glitch (or the first of a real jump)
  std::uint64_t total() const { return bad_rate + bad_angle + bad_stamp + duplicate + out_of_order + stamp_jump; }
};

/// What the session measured of the table's clock against the gyro's.
struct TableClockReport {
  bool measured = false;           ///< a turntable stream was read
  double configured_offset = 0.0;  ///< s, subtracted from the table's stamps (table_clock/offset)
  TableStampStatistics stamps;     ///< the regularisation of a fixed-rate log: jitter, steps
  TableClockOffsetResult offset;   ///< the offset left after the configured one, from the changes of rate
  double k_scaled = 1.0;           ///< K was multiplied by this for the clocks' rate difference
};

/// What the field method measured besides D(theta) (method field): the realised gain of the virtual
/// rate, the drift as measured before the Earth rate's share came off, and how the session went.
struct FieldReport {
  bool present = false;
  HarmonicFitResult virtual_rate_gain;                ///< G_v(theta): realised over commanded virtual rate
  HarmonicFitResult measured_drift;                   ///< D(theta) + K(theta) Omega_s, rad/s: the still gyro's rate
  double earth_rate = 0.0;                            ///< Omega_s, rad/s: the prior's vertical Earth rate
  double k0_prior = 0.0;                              ///< the prior's K0, kept
  double positive_rate = 0.0, negative_rate = 0.0;    ///< rad/s, the commanded rates of the two directions
  double positive_turns = 0.0, negative_turns = 0.0;  ///< full turns (2 pi) of theta in each direction's data
  double positive_time = 0.0, negative_time = 0.0;    ///< s of each direction's settled data
  /// The standard errors of D's harmonics over what the white wave-angle noise alone predicts (rms of
  /// the ratios, >= 1): the stillness of the case (a case that moves, or a gyro's own rate noise,
  /// raises it)
  double excess_scatter = 1.0;
};

struct GroupSummary {
  double rate = 0.0;      ///< mean table rate, rad/s
  double rate_std = 0.0;  ///< rad/s
  double duration = 0.0;  ///< s of wave data
  std::uint64_t samples = 0;
  double coverage = 0.0;  ///< fraction of theta bins
  double turns = 0.0;     ///< electrical angle swept / pi
};

struct GateResult {
  std::string name;
  bool passed = false;
  double value = 0.0;
  double limit = 0.0;
  std::string message;
};

struct CalibrationOutcome {
  CalibrationMethodKind method = CalibrationMethodKind::kDualRate;
  bool accepted = false;
  std::string reason;                           ///< first failed gate, or why no estimate exists
  GyroParameters parameters;                    ///< prior with the new estimates (meaningful when accepted)
  std::vector<HarmonicFitResult> scale_factor;  ///< one entry (or one per frequency node)
  std::vector<HarmonicFitResult> drift;
  std::vector<double> frequency_nodes;  ///< Hz; empty when frequency independent
  bool has_correction = false;
  CorrectionMatrixEstimator::Result correction;
  double coverage = 0.0;
  double smoothing_factor = 1.0;
  double error_bound = 0.0;       ///< the paper's bound for K (dimensionless)
  double nonlinearity_ppm = 0.0;  ///< peak |K(theta) - K0| / |K0| of the fitted model
  double duration = 0.0;          ///< s of data used
  std::uint64_t samples = 0;
  std::vector<GroupSummary> plateaus;
  std::vector<GateResult> gates;
  std::vector<BinnedCurvePoint> binned;  ///< binned K and D (dual-rate) or step points
  std::vector<std::string> notes;
  double quadrature_ratio = 0.0;  ///< mean |B/A| of the wave samples (F of the diagnosis)
  /// Records of the rotation's stream received (all runs of the session): turntable states, or in a
  /// field run precession states. The report keeps the keys turntable_records, turntable_rejected.
  std::uint64_t rotation_records = 0;
  RotationRecordRejects rotation_rejected;  ///< of them, dropped as glitches
  std::uint64_t restarts = 0;               ///< times a stream went back for good and the run started over
  std::vector<DefectDiagnosis> diagnosis;   ///< one per scale_factor fit with 2 and 4 theta terms
  /// dual-rate: the bias's trend fitted with K and D (order 0: none was fitted). The written D0 is
  /// the bias at bias_trend.reference_stamp, the mean time of the data.
  BiasTrendFit bias_trend;
  /// dual-rate: the bias's random walk estimated from the fit's residuals; when carried, the
  /// standard errors include what it predicts.
  BiasWalkFit bias_walk;
  /// dual-rate, where the caller modelled it (a triad's axis): the Earth's horizontal rate each
  /// fixture position's tilt let in, fitted with K and D.
  std::vector<HorizontalEarthFit> horizontal_earth;
  TableClockReport table_clock;
  FieldReport field;  ///< method field only

  /// Appends a gate; the first failing one becomes the reason.
  void gate(const std::string& name, bool passed, double value, double limit, const std::string& message);
  /// accepted = every gate passed (and at least one exists).
  void decide();
};

/// ISO 8601 UTC time of now, for CalibrationProvenance::time.
std::string utcNow();
/// Highest harmonic order fitted for K or D (2 if none): what the window smoothing is sized for.
int maxFittedOrder(const std::vector<int>& scale_factor_orders, const std::vector<int>& drift_orders);

/// Fills outcome->diagnosis from its scale-factor fits, read against the P in force during the run.
void diagnose(CalibrationOutcome* outcome, const CorrectionMatrix& correction_in_force);

/// Human- and machine-readable YAML of the outcome (report files, plots).
std::string emitCalibrationReport(const CalibrationOutcome& outcome);
/// The `gates` and `notes` keys of a report, into an open map (the single-axis and triad reports).
void emitGatesAndNotes(YAML::Emitter& out, const std::vector<GateResult>& gates, const std::vector<std::string>& notes);

}  // namespace core
}  // namespace hrg_gyro
