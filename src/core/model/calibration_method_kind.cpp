#include "hrg_gyro/core/model/calibration_method_kind.h"

#include <stdexcept>

namespace hrg_gyro {
namespace core {
namespace {

struct Entry {
  CalibrationMethodKind kind;
  CalibrationMethodTraits traits;
};

// The methods, listed once. Columns: name, description, generator pairs, turntable, K and D, P,
// frequency dependent, three axes, virtual rotation.
const Entry kMethods[] = {
    {CalibrationMethodKind::kDualRate,
     {"dual_rate", "two opposite table rates: K(theta) and D(theta), the drift cancels", false, true, true, false,
      false, false, false}},
    {CalibrationMethodKind::kConstantRate,
     {"constant_rate", "a dwell then one table rate: K(theta) and D", false, true, true, false, false, false, false}},
    {CalibrationMethodKind::kStep,
     {"step", "table steps between dwells: K(theta) from the steps, D from the dwells", false, true, true, false, false,
      false, false}},
    {CalibrationMethodKind::kCorrectionMatrix,
     {"correction_matrix", "generator sweep at rest: the correction matrix P", true, false, false, true, false, false,
      false}},
    {CalibrationMethodKind::kThermal,
     {"thermal", "dual rate across temperature: K and D as splines over the resonator frequency", false, true, true,
      false, true, false, false}},
    {CalibrationMethodKind::kTriad,
     {"triad",
      "three axes in a fixture turned through positions: each axis's K(theta) and D(theta), the triad's matrix and "
      "bias",
      false, true, true, false, false, true, false}},
    {CalibrationMethodKind::kField,
     {"field",
      "a still gyro, no table: its precession loop turns the wave both ways; D(theta) and the virtual rate's gain, K "
      "kept",
      false, false, false, false, false, false, true}},
};

const Entry& entryOf(CalibrationMethodKind method) {
  for (const Entry& e : kMethods) {
    if (e.kind == method) return e;
  }
  throw std::invalid_argument("calibration method out of range");
}

}  // namespace

const std::vector<CalibrationMethodKind>& allCalibrationMethods() {
  static const std::vector<CalibrationMethodKind> all = [] {
    std::vector<CalibrationMethodKind> v;
    for (const Entry& e : kMethods) v.push_back(e.kind);
    return v;
  }();
  return all;
}

const CalibrationMethodTraits& traitsOf(CalibrationMethodKind method) { return entryOf(method).traits; }

std::string nameOf(CalibrationMethodKind method) { return traitsOf(method).name; }

std::string calibrationMethodNames(const std::string& separator) {
  std::string out;
  for (const Entry& e : kMethods) out += (out.empty() ? "" : separator) + std::string(e.traits.name);
  return out;
}

std::string singleAxisMethodNames(const std::string& separator) {
  std::string out;
  for (const Entry& e : kMethods) {
    if (!e.traits.three_axes) out += (out.empty() ? "" : separator) + std::string(e.traits.name);
  }
  return out;
}

std::optional<CalibrationMethodKind> findCalibrationMethod(const std::string& name) {
  for (const Entry& e : kMethods) {
    if (name == e.traits.name) return e.kind;
  }
  return std::nullopt;
}

CalibrationMethodKind parseCalibrationMethod(const std::string& name) {
  const std::optional<CalibrationMethodKind> m = findCalibrationMethod(name);
  if (!m) throw std::invalid_argument("unknown method '" + name + "' (" + calibrationMethodNames() + ")");
  return *m;
}

namespace {
const char* const kNoneName = "none";
const char* const kManualName = "manual";
}  // namespace

ParameterOrigin ParameterOrigin::manual() {
  ParameterOrigin o;
  o.kind_ = Kind::kManual;
  return o;
}

ParameterOrigin ParameterOrigin::calibratedBy(CalibrationMethodKind method) {
  ParameterOrigin o;
  o.kind_ = Kind::kMethod;
  o.method_ = method;
  return o;
}

ParameterOrigin ParameterOrigin::parse(const std::string& text) {
  if (text == kNoneName) return none();
  if (text == kManualName) return manual();
  const std::optional<CalibrationMethodKind> m = findCalibrationMethod(text);
  if (!m) {
    throw std::invalid_argument("unknown calibration method '" + text + "' (" + kNoneName + ", " + kManualName + ", " +
                                calibrationMethodNames() + ")");
  }
  return calibratedBy(*m);
}

std::optional<CalibrationMethodKind> ParameterOrigin::method() const {
  if (kind_ != Kind::kMethod) return std::nullopt;
  return method_;
}

std::string ParameterOrigin::name() const {
  switch (kind_) {
    case Kind::kNone:
      return kNoneName;
    case Kind::kManual:
      return kManualName;
    case Kind::kMethod:
      break;
  }
  return nameOf(method_);
}

}  // namespace core
}  // namespace hrg_gyro
