// The interface every calibration method implements, and the samples it receives.
//
// The session (calibration_session.h) synchronises the wave with the rotation it is measured against
// (the turntable's, or in a field run the rotation the precession loop commands) and hands each
// method only samples taken on a settled plateau of that rotation, labelled with that plateau. A method
// accumulates in memory that does not grow with the session length, says when its data are
// complete, and turns them into a CalibrationOutcome with its quality gates.
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "hrg_gyro/core/calibration/calibration_outcome.h"
#include "hrg_gyro/core/calibration/calibration_settings.h"
#include "hrg_gyro/core/estimation/plateau_detector.h"
#include "hrg_gyro/core/model/wave_parameters.h"

namespace hrg_gyro {
namespace core {

struct PlateauSample {
  Nanoseconds stamp = 0;
  double theta = 0.0;      ///< measured electrical angle, rad (continuous)
  double frequency = NAN;  ///< Hz
  PlateauState plateau;    ///< settled plateau this sample belongs to
  /// rad, a continuous angle of the rotation at the stamp -- the table's, or in a field run the
  /// commanded virtual angle psi: the logged angle interpolated, or (in a rate-only turntable stream,
  /// angle_logged false) the integral of the reported rate.
  double rotation_angle = 0.0;
  double rotation_rate = 0.0;  ///< rad/s, as reported, interpolated at the stamp
  bool angle_logged = false;   ///< the rotation's stream logs its angle (a precession state always does)
  /// rad^2: the variance the regularised stamps (table_stamp_regulariser.h) leave on rotation_angle,
  /// an error smooth in time that the angle's own scatter does not show (0: stamps as logged).
  double angle_smooth_error = 0.0;
  /// Where the caller models the Earth's horizontal rate (a triad's axis on the table,
  /// CalibrationSession::modelHorizontalEarthRate): the fixture position's slot whose tilt the sample
  /// carries (-1: none), and psi, the heading of the platter's x (the table's azimuth minus its angle), rad.
  int horizontal_slot = -1;
  double horizontal_phase = 0.0;
};

struct CalibrationProgress {
  double fraction = 0.0;  ///< 0..1 towards complete()
  std::string summary;    ///< one line for logs and diagnostics
};

class CalibrationMethod {
 public:
  virtual ~CalibrationMethod() = default;
  virtual CalibrationMethodKind kind() const = 0;
  virtual void addSample(const PlateauSample& sample) = 0;
  /// Generator pairs: raw channel amplitudes and the known wave's ideal ones.
  virtual void addGeneratorPair(const ChannelVector& /*raw*/, const ChannelVector& /*reference*/) {}
  virtual bool complete() const = 0;
  virtual CalibrationProgress progress() const = 0;
  virtual CalibrationOutcome finish(const GyroParameters& prior) const = 0;
  /// Fit the Earth's horizontal rate of `slots` fixture positions with the method's model (before
  /// any sample). False: the method does not model it (the samples' horizontal slots are ignored).
  virtual bool modelHorizontalEarthRate(int /*slots*/) { return false; }
};

/// The method the settings choose; `prior` is the parameter set the data are measured with.
std::unique_ptr<CalibrationMethod> makeCalibrationMethod(const CalibrationSettings& settings,
                                                         const GyroParameters& prior);

}  // namespace core
}  // namespace hrg_gyro
