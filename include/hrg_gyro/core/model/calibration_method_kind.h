// Which calibration method a run uses, as a type: the one list of the methods, their names in
// files, parameters and command lines, and what each needs from a session (traits). Everything
// else asks this header instead of comparing names: a new method is added here once, and every
// front-end, help text and check follows.
//
// Not to be confused with CalibrationMethod (calibration_method_interface.h), the interface a method's
// implementation fulfils; makeCalibrationMethod() turns a kind into that implementation.
//
// A parameter file also records where its numbers came from (calibration.method): a method, or
// "none" (the nominal, uncalibrated model) or "manual" (edited by hand). ParameterOrigin is that
// provenance; its text form is the file's, unchanged.
#pragma once

#include <optional>
#include <string>
#include <vector>

namespace hrg_gyro {
namespace core {

enum class CalibrationMethodKind {
  kDualRate,          ///< two opposite table rates: K(theta) and D(theta), drift cancels
  kConstantRate,      ///< a dwell then one rate: K(theta) and D; drift harmonics leak into K
  kStep,              ///< table steps between dwells: K from the steps, D from the dwells
  kCorrectionMatrix,  ///< generator sweep at rest: the correction matrix P
  kThermal,           ///< dual-rate across temperature: K and D as splines over the frequency
  kTriad,             ///< three axes in a fixture turned through positions: each axis's K and D, the triad's M and bias
  kField,             ///< a still gyro, its wave turned both ways by the precession loop: D(theta), K kept
};

/// What a method needs from a session and what it estimates.
struct CalibrationMethodTraits {
  const char* name;           ///< the name in files, parameters and command lines
  const char* description;    ///< one line for help texts
  bool uses_generator_pairs;  ///< fed raw channels paired with the generator reference (the truth
                              ///< stream), finishes when the sweep ends; else fed the wave on plateaus
  bool needs_turntable;       ///< needs the turntable state stream
  bool estimates_k_and_d;     ///< writes K(theta) and D(theta)
  bool estimates_correction;  ///< writes the correction matrix P
  bool frequency_dependent;   ///< K and D over the resonator frequency (the input must carry it)
  bool three_axes;            ///< calibrates a triad (three axes' streams and the fixture's position)
  /// fed the precession loop's state (precession/state) instead of the turntable's: the virtual
  /// rotation of a still gyro stands in for the table (refreshes D(theta), keeps K)
  bool virtual_rotation;
};

/// Every method, in the order help texts list them; the first is the default.
const std::vector<CalibrationMethodKind>& allCalibrationMethods();
const CalibrationMethodTraits& traitsOf(CalibrationMethodKind method);
/// The method's name, e.g. "dual_rate".
std::string nameOf(CalibrationMethodKind method);
/// The names of every method joined by `separator`, e.g. "dual_rate, constant_rate, ...".
std::string calibrationMethodNames(const std::string& separator = ", ");
/// The same for the methods of one axis (those that are not three_axes).
std::string singleAxisMethodNames(const std::string& separator = ", ");
/// The method named `name`; nullopt for an unknown name.
std::optional<CalibrationMethodKind> findCalibrationMethod(const std::string& name);
/// The method named `name`; throws std::invalid_argument "unknown method 'x' (dual_rate, ...)".
CalibrationMethodKind parseCalibrationMethod(const std::string& name);

/// Provenance of a parameter set: none (nominal model), manual, or the method that calibrated it.
class ParameterOrigin {
 public:
  ParameterOrigin() = default;  ///< none
  static ParameterOrigin none() { return ParameterOrigin(); }
  static ParameterOrigin manual();
  static ParameterOrigin calibratedBy(CalibrationMethodKind method);
  /// "none", "manual" or a method name; throws std::invalid_argument listing them all otherwise.
  static ParameterOrigin parse(const std::string& text);

  bool isNone() const { return kind_ == Kind::kNone; }
  bool isManual() const { return kind_ == Kind::kManual; }
  /// The calibration method, when a method produced the set.
  std::optional<CalibrationMethodKind> method() const;
  /// The file's text: "none", "manual" or the method's name.
  std::string name() const;

  bool operator==(const ParameterOrigin& o) const { return kind_ == o.kind_ && method_ == o.method_; }
  bool operator!=(const ParameterOrigin& o) const { return !(*this == o); }

 private:
  enum class Kind { kNone, kManual, kMethod };
  Kind kind_ = Kind::kNone;
  CalibrationMethodKind method_ = CalibrationMethodKind::kDualRate;  // meaningful for kMethod only
};

}  // namespace core
}  // namespace hrg_gyro
