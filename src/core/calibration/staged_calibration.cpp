#include "hrg_gyro/core/calibration/staged_calibration.h"

#include <stdexcept>

namespace hrg_gyro {
namespace core {

StagedCalibration::StagedCalibration(const CalibrationSettings& base, std::vector<CalibrationMethodKind> stages)
    : base_(base), current_(base.method) {
  rewind(std::move(stages));
  current_ = stages_.front();
}

bool StagedCalibration::usesGeneratorPairs() const {
  for (CalibrationMethodKind m : stages_) {
    if (traitsOf(m).uses_generator_pairs) return true;
  }
  return false;
}

void StagedCalibration::rewind() { next_ = 0; }

void StagedCalibration::rewind(std::vector<CalibrationMethodKind> stages) {
  stages_ = stages.empty() ? std::vector<CalibrationMethodKind>{base_.method} : std::move(stages);
  next_ = 0;
}

CalibrationSession& StagedCalibration::startNextStage(const GyroParameters& prior) {
  if (!hasNextStage()) throw std::logic_error("no calibration stage left to start");
  return start(stages_[next_++], prior);
}

CalibrationSession& StagedCalibration::restartStage(const GyroParameters& prior) { return start(current_, prior); }

CalibrationSession& StagedCalibration::start(CalibrationMethodKind method, const GyroParameters& prior) {
  session_.reset();
  current_ = method;
  CalibrationSettings settings = base_;
  settings.method = method;
  session_ = std::make_unique<CalibrationSession>(settings, prior);
  return *session_;
}

CalibrationOutcome StagedCalibration::finishStage() {
  if (!session_) throw std::logic_error("no calibration run in progress");
  CalibrationOutcome o = session_->finish();
  session_.reset();
  return o;
}

void StagedCalibration::abort() {
  session_.reset();
  next_ = stages_.size();
}

std::string StagedCalibration::defaultReportPath(const std::string& parameter_file) {
  std::string path = parameter_file;
  const std::string yaml = ".yaml";
  if (path.size() > yaml.size() && path.compare(path.size() - yaml.size(), yaml.size(), yaml) == 0) {
    path.resize(path.size() - yaml.size());
  }
  return path + ".report.yaml";
}

std::string StagedCalibration::stageReportPath(const std::string& report_file, CalibrationMethodKind method) {
  std::string path = report_file;
  const std::size_t dot = path.rfind(".report.yaml");
  if (dot != std::string::npos) path.insert(dot, "." + nameOf(method));
  return path;
}

}  // namespace core
}  // namespace hrg_gyro
