// A calibration in stages: several methods run one after the other, each on the parameters the
// previous one wrote. [correction_matrix, dual_rate] is the two-stage refinement: P first from the
// generator sweep, then the residual K and D measured through the new P. A single method is one
// stage. This class holds the sequence, the session of the stage in progress and the naming of
// each stage's report; the front-end supplies the prior of each stage (it re-reads the parameter
// file the previous stage wrote) and decides whether to go on (only after a written result).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "hrg_gyro/core/calibration/calibration_session.h"

namespace hrg_gyro {
namespace core {

class StagedCalibration {
 public:
  /// `stages` empty: the one stage of `base.method`. Each stage runs with `base` and its own method.
  StagedCalibration(const CalibrationSettings& base, std::vector<CalibrationMethodKind> stages = {});

  const std::vector<CalibrationMethodKind>& stages() const { return stages_; }
  /// Whether some stage feeds on generator pairs (the front-end then listens to channels and truth).
  bool usesGeneratorPairs() const;

  /// Back to the first stage (of `stages` when given, which replaces the sequence); nothing runs.
  void rewind();
  void rewind(std::vector<CalibrationMethodKind> stages);
  bool hasNextStage() const { return next_ < stages_.size(); }
  /// The stage startNextStage() starts (requires hasNextStage()).
  CalibrationMethodKind nextStage() const { return stages_.at(next_); }
  /// The method of the stage started last (before any: the first stage's).
  CalibrationMethodKind current() const { return current_; }
  /// The next stage starts on `prior` (the stage counts as taken even if this throws, e.g. for a
  /// prior the method cannot use: there is then no run in progress). Throws std::logic_error when
  /// no stage is left.
  CalibrationSession& startNextStage(const GyroParameters& prior);
  /// The stage in progress starts over on `prior` (a bag loop or a restarted driver).
  CalibrationSession& restartStage(const GyroParameters& prior);

  /// The run in progress, or nullptr.
  CalibrationSession* session() { return session_.get(); }
  const CalibrationSession* session() const { return session_.get(); }
  /// Fits and gates the run in progress and ends it (the next stage, if any, is left to start).
  CalibrationOutcome finishStage();
  /// Ends the run in progress, if any, and drops the remaining stages.
  void abort();

  /// `<parameter file without .yaml>.report.yaml`: the report file when none is configured.
  static std::string defaultReportPath(const std::string& parameter_file);
  /// One report per stage, so a staged session keeps them all: `x.report.yaml` -> `x.<method>.report.yaml`.
  static std::string stageReportPath(const std::string& report_file, CalibrationMethodKind method);

 private:
  CalibrationSession& start(CalibrationMethodKind method, const GyroParameters& prior);

  CalibrationSettings base_;
  std::vector<CalibrationMethodKind> stages_;
  std::size_t next_ = 0;
  CalibrationMethodKind current_;
  std::unique_ptr<CalibrationSession> session_;
};

}  // namespace core
}  // namespace hrg_gyro
