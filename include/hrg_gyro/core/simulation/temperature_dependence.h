// How the simulated gyro depends on temperature (scenario section `thermal`).
//
// Why: the paper's K(theta, f) exists because the resonance frequency f tracks the resonator
// temperature T and the defects move with T as well. A scenario with a thermal section describes
// the gyro of its `resonator` and `pickoff` sections at a reference temperature Tref, a temperature
// profile over the session, and linear temperature coefficients:
//   f(T)         = f0 + frequency_coefficient (T - Tref)            reported resonance frequency, Hz
//   A(T)         = A (1 + amplitude (T - Tref))                     wave amplitude; the electrode gap
//                                                                   d0 is fixed, so A/d0 moves with A
//   delta_i(T)   = delta_i + misplacement[i] (T - Tref)             pickoff misplacement, rad
//   g_i(T)       = g_i + gain_error[i] (T - Tref)                   pickoff gain error
//   K(theta, T)  = K(theta, f(T)) + scale_factor(theta) (T - Tref)  intrinsic scale factor
//   D(theta, T)  = D(theta, f(T)) + drift(theta) (T - Tref)         intrinsic drift, rad/s
// (the resonator's own K and D may already be frequency dependent; they are evaluated at f(T)).
//
// Simplification, documented in docs/simulation.md: the signal is still sampled and demodulated at
// the nominal f0; only the reported frequency follows f(T). Demodulation is synchronous with the drive,
// so the amplitudes do not depend on the carrier frequency; what matters for the calibration is
// that the reported f is a faithful temperature proxy.
#pragma once

#include <array>

#include "hrg_gyro/core/common/yaml_field.h"
#include "hrg_gyro/core/model/harmonic_model.h"
#include "hrg_gyro/core/signal/pickoff_array.h"
#include "hrg_gyro/core/simulation/temperature_profile.h"

namespace hrg_gyro {
namespace core {

/// Linear temperature coefficients of the defects, per degC.
struct ThermalCoefficients {
  double amplitude = 0.0;                            ///< relative change of A per degC
  std::array<double, kPickoffCount> misplacement{};  ///< rad/degC, sensors 0..7
  std::array<double, kPickoffCount> gain_error{};    ///< 1/degC, sensors 0..7
  HarmonicModel scale_factor{0.0};                   ///< dK/dT (mean and harmonics), 1/degC
  HarmonicModel drift{0.0};                          ///< dD/dT, rad/s per degC
};

struct ThermalConfig {
  bool enabled = false;                 ///< false: no thermal section, the gyro has no temperature
  double reference_temperature = 25.0;  ///< degC at which the resonator and pickoff sections hold
  double frequency_coefficient = 0.0;   ///< df/dT, Hz/degC
  TemperatureProfile profile;           ///< T over the session (t from the session start)
  ThermalCoefficients coefficients;

  double frequencyAt(double temperature, double nominal_frequency) const {
    return nominal_frequency + frequency_coefficient * (temperature - reference_temperature);
  }

  /// Parses the `thermal` section. Throws ConfigError naming the key. The limits that depend on
  /// the rest of the gyro are checked by SimulationConfig::parse.
  static ThermalConfig parse(const YamlField& section);
};

/// Everything of the gyro that depends on temperature, evaluated at one temperature.
struct GyroAtTemperature {
  double temperature = 0.0;  ///< degC
  double frequency = 0.0;    ///< Hz, reported resonance frequency
  double amplitude = 0.0;    ///< A
  PickoffDefects pickoff;
  HarmonicModel scale_factor{0.0};  ///< intrinsic K(theta) at this temperature (frequency independent)
  HarmonicModel drift{0.0};         ///< intrinsic D(theta), rad/s
};

/// The gyro whose reference-temperature description is (f0, amplitude, pickoff, k, d) at `temperature`.
GyroAtTemperature gyroAtTemperature(const ThermalConfig& thermal, double temperature, double nominal_frequency,
                                    double amplitude, const PickoffDefects& pickoff, const HarmonicModel& k,
                                    const HarmonicModel& d);

/// value(theta) = a(theta, f) + s b(theta) as one frequency-independent model over the union of the
/// orders (a evaluated at frequency f; b must be frequency independent).
HarmonicModel combineModels(const HarmonicModel& a, double frequency, const HarmonicModel& b, double s);

}  // namespace core
}  // namespace hrg_gyro
