// The virtual rotation a field calibration commands, planned from its settings: a rest at 0, then
// one segment per entry of `directions`, each at +-rate for long enough that its settled data sweep
// `turns` full turns of theta (the plateau's settle time first, half a smoothing span lost at its
// end, a second to spare), then 0 again. The live calibrator sends these commands on
// command/precession; a scenario's dynamics.commands may carry the same plan for an offline session.
//
// What the plan's rate costs: a wave precessed faster leaves the loops further behind, and the part
// of that lag which keeps its sign both ways reads as drift (precessionLagDrift). For a gyro whose
// resonator the settings describe (field.resonator), fieldLoopLag predicts it.
//
// FieldPlanRun is the plan under way in a live run, on the stream time of the precession state (the
// driver's stamps): when it starts (the first state while the driver listens), which command is due,
// whether what the driver reports is what this run commanded, and when a run that ends must command
// the rate 0. A run cannot go on when the precession loop executes a command this run did not send
// -- named by the driver as another node's, a rate this run did not command, or more commands than
// it sent from a driver that names nobody -- and cannot complete once its plan is over without the
// data it needed: both end it with a reason instead of leaving it waiting. FieldPlanRun::step does
// all of it for one precession state; the live calibrator sends the commands and ends the run.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "hrg_gyro/core/calibration/calibration_outcome.h"
#include "hrg_gyro/core/calibration/calibration_session.h"
#include "hrg_gyro/core/calibration/calibration_settings.h"
#include "hrg_gyro/core/common/units.h"

namespace hrg_gyro {
namespace core {

struct PlannedPrecession {
  double time = 0.0;  ///< s from the start of the plan
  double rate = 0.0;  ///< rad/s, electrical, commanded from `time` on
};

/// The commands in order; the last one (rate 0) ends the virtual rotation. Throws
/// std::invalid_argument when the plan would last longer than kMaxFieldPlanDuration (or for ever).
std::vector<PlannedPrecession> fieldCommandPlan(const CalibrationSettings& settings);
// The plan's length (fieldSegmentDuration, fieldPlanDuration, fieldPlanLengthProblem) is part of
// its settings: calibration_settings.h, which checks it when the settings are read.

/// The largest drift (rad/s, the peak over theta) the loops' lag adds to a wave precessed at `rate`
/// for the gyro of field.resonator; NaN when that is unknown.
double fieldLoopLag(const FieldSettings& field, double rate);
/// Throws std::invalid_argument when the planned run cannot be carried out or cannot pass: a plan
/// too long, or (field.resonator known) a loop lag at field.rate above field.max_drift_std, which
/// the loop_lag gate (the lag within the largest standard error of a D term, itself within
/// max_drift_std) would always refuse. The live calibrator calls it before commanding anything.
void checkFieldPlan(const CalibrationSettings& settings);

/// One record of the precession loop's state as the plan reads it (PrecessionState.msg).
struct PrecessionReport {
  Nanoseconds stamp = 0;
  double rate = 0.0;           ///< rad/s, the commanded rate in force
  std::uint64_t commands = 0;  ///< executed since the driver started
  std::string source;          ///< who commanded the rate in force ("" when the driver does not say)
};

/// What one precession state asks of the calibrator running the plan.
struct FieldPlanStep {
  /// Not empty: the precession loop executed a command this run did not send; the run is aborted
  /// for this reason (nothing else is due).
  std::string foreign;
  std::vector<PlannedPrecession> due;  ///< the commands due, in order: send them
  /// Not empty: the plan is over and the data incomplete; the run is finished, refused for this reason.
  std::string overdue;
};

class FieldPlanRun {
 public:
  /// s of stream time after the plan's last command within which incomplete data may still complete:
  /// the settle time and a smoothing span (the last samples are classified that late) and a second.
  static double overdueMargin(const CalibrationSettings& settings);
  /// s more of the precession state's stream time after which a wave stream that has not got there
  /// (stopped, or far behind) is not waited for.
  static constexpr double kWaveStreamWait = 30.0;
  /// Rates agree within this much relative to the rate (and 1e-12 rad/s): a driver may report the
  /// rate it executes in single precision.
  static constexpr double kRateTolerance = 1e-6;

  FieldPlanRun() = default;  ///< no plan
  /// `self`: this calibrator's node name as a driver sees the publisher of its commands. Throws
  /// std::invalid_argument for a plan that cannot run or cannot pass (checkFieldPlan): nothing is
  /// commanded for it.
  FieldPlanRun(const CalibrationSettings& settings, std::string self);

  bool empty() const { return plan_.empty(); }
  bool started() const { return started_; }
  const std::vector<PlannedPrecession>& plan() const { return plan_; }
  std::size_t sent() const { return sent_rates_.size(); }
  /// The plan's clock starts with `report` (the first precession state while the driver listens).
  void start(const PrecessionReport& report);
  /// The next planned command due at stream time `now` (false: none yet, or the plan is over); the
  /// caller sends it.
  bool nextDue(Nanoseconds now, PlannedPrecession* command);
  /// Between its first command and its last the plan has the wave turning.
  bool midway() const { return next_ > 0 && next_ < plan_.size(); }
  /// The run ends before its plan: the caller commands 0 (recorded as this run's); nothing more is due.
  void stop();
  /// The run ends (finished, aborted, restarted): true when its plan had the wave turning (midway);
  /// it is then stopped and the caller commands 0.
  bool end();
  /// The run started over (a stream went back for good): the plan starts again from the next
  /// precession state, nothing sent yet.
  void restart();

  /// One precession state of the run: judged (check); the plan started on it if it waits and
  /// `driver_listens()` (asked only then: commands sent before the driver listens would be lost);
  /// the commands due; and, the session's data incomplete, whether the plan is overdue (`wave_now`:
  /// the newest wave stamp, 0 none).
  FieldPlanStep step(const PrecessionReport& report, const std::function<bool()>& driver_listens,
                     const CalibrationSession& session, Nanoseconds wave_now);

  /// "" when the state is what this run commanded (or none of its commands has been executed yet);
  /// otherwise why the run cannot go on. Records at or before the last one checked are not judged
  /// (a stream going back is the session's to handle).
  std::string check(const PrecessionReport& report);
  /// For a run whose data are incomplete: "" while they still may complete; otherwise why they
  /// cannot, `progress` saying what the data hold. `state_now`, `wave_now`: the newest stamps of the
  /// precession state and of the wave (0: none).
  std::string overdue(Nanoseconds state_now, Nanoseconds wave_now, const std::string& progress) const;

 private:
  std::vector<PlannedPrecession> plan_;
  double margin_ = 0.0;
  std::string self_;
  std::string needed_;  // what each direction's data need, in words
  std::size_t next_ = 0;
  std::vector<double> sent_rates_;
  bool started_ = false;
  Nanoseconds start_ = 0;
  std::uint64_t base_commands_ = 0;  // the driver's count when the plan started
  Nanoseconds last_checked_ = 0;
};

/// Ends an outcome as refused for `gate` ("precession_command": a command this run did not send;
/// "plan": the plan is over without the data), that gate first and its message the reason; the
/// gates the fit gave (if any) follow.
void refuseFieldRun(CalibrationOutcome* outcome, const std::string& gate, const std::string& message);

}  // namespace core
}  // namespace hrg_gyro
