// Everything the processor needs to turn channel amplitudes into a compensated angle: the K and D
// harmonic models, the correction matrix P, the Earth-rate setting, and where the numbers came from.
// One instance is the in-memory form of one parameter file (parameter_file.h).
#pragma once

#include <string>

#include "hrg_gyro/core/common/units.h"
#include "hrg_gyro/core/model/calibration_method_kind.h"
#include "hrg_gyro/core/model/correction_matrix.h"
#include "hrg_gyro/core/model/earth_rate.h"
#include "hrg_gyro/core/model/harmonic_model.h"

namespace hrg_gyro {
namespace core {

/// Nominal electrical scale factor of an uncalibrated gyro: K0 = -2 k with the Bryan factor
/// k ~ 0.28 of a hemispherical shell (see docs/math.md, "Conventions").
constexpr double kNominalScaleFactor = -0.56;

struct EarthRateSettings {
  bool enabled = true;
  double latitude = 0.0;  ///< geodetic latitude, rad (north positive); the gyro axis is local vertical
  double verticalRate() const { return enabled ? verticalEarthRate(latitude) : 0.0; }
  bool operator==(const EarthRateSettings& o) const { return enabled == o.enabled && latitude == o.latitude; }
};

/// Provenance of a parameter set, written by the calibrator.
struct CalibrationProvenance {
  ParameterOrigin method;  ///< none, manual or the calibration method (its text form in the file)
  std::string time;        ///< ISO 8601 UTC
  std::string source;      ///< "live" or the bag it came from
  std::string notes;
  bool operator==(const CalibrationProvenance& o) const {
    return method == o.method && time == o.time && source == o.source && notes == o.notes;
  }
};

struct GyroParameters {
  HarmonicModel scale_factor{kNominalScaleFactor};  ///< K(theta, f) = d theta / d alpha, dimensionless
  HarmonicModel drift{0.0};                         ///< D(theta, f), rad/s of electrical angle
  CorrectionMatrix correction;                      ///< P of (E - P) Z
  EarthRateSettings earth_rate;
  CalibrationProvenance calibration;

  bool operator==(const GyroParameters& o) const {
    return scale_factor == o.scale_factor && drift == o.drift && correction == o.correction &&
           earth_rate == o.earth_rate && calibration == o.calibration;
  }
  bool operator!=(const GyroParameters& o) const { return !(*this == o); }
};

}  // namespace core
}  // namespace hrg_gyro
