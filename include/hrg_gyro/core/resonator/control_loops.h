// The control loops of a whole-angle gyro, as they act on the averaged equations: they sample the
// wave (A, B, theta, tau) at the control rate and command, until the next sample, a force in the
// wave's frame and the frequency of the reference carrier.
//   - Energy: holds E = A^2 + B^2 at its setpoint against damping with a force at the antinode in
//     phase with the velocity (a_v = c / (2A), so that dE/dt = c + the damping's share).
//   - Quadrature: drives B to 0 against the frequency split with a force at the node in phase with
//     the displacement (dB/dt = n_d + the split's share).
//   - Phase (the phase-locked loop): holds tau at its setpoint by moving the reference carrier,
//     dtau/dt = -dw_r + the wave's own frequency offset; dw_r is what a real gyro reports as its
//     resonance frequency (f0 + dw_r / 2 pi).
//   - Precession (virtual rotation): turns the wave at a commanded electrical rate w_v with a force
//     at the node in phase with the velocity, n_v = w_v (A^2 - B^2) / A, which an ideal drive turns
//     into dtheta/dt = w_v whatever the quadrature. Open loop: no sensor checks the rate realised,
//     so the drive chain's errors (drive_chain.h) remain in it.
// Energy, quadrature and phase are PI loops on plants that are integrators, designed as second-order
// loops of natural frequency 2 pi bandwidth and the given damping ratio (kp = 2 zeta wn, ki = wn^2),
// integrated once per control period. A bandwidth of 0 opens that loop.
#pragma once

#include "hrg_gyro/core/model/wave_parameters.h"
#include "hrg_gyro/core/resonator/averaged_resonator.h"

namespace hrg_gyro {
namespace core {

/// rad/s, electrical: the largest |rate| a precession command may carry. The field method's
/// field/rate, a scenario's dynamics.commands and driver_sim's command/precession are held to it.
constexpr double kMaxPrecessionRate = 10.0;

struct LoopSettings {
  double energy = 1.0;                        ///< E setpoint, amplitude units squared
  double energy_bandwidth = 5.0;              ///< Hz; 0 opens the loop
  double quadrature_bandwidth = 20.0;         ///< Hz; 0 opens the loop
  double phase = 0.3;                         ///< tau setpoint, rad
  double phase_bandwidth = 20.0;              ///< Hz; 0 opens the loop (the carrier stays at f0)
  double damping_ratio = 0.7071067811865476;  ///< zeta of every loop
  /// Hz: the loops sample the wave and update their command this often, and hold it in between.
  double control_rate = 5000.0;

  /// Throws std::invalid_argument naming the field: all finite, energy > 0, bandwidths >= 0 and
  /// below a tenth of the control rate (a sampled loop that fast is no longer the loop designed),
  /// damping ratio > 0, control rate > 0.
  void validate() const;
  /// The PI gains of a loop of the given bandwidth (Hz): kp = 2 zeta wn (1/s), ki = wn^2 (1/s^2).
  double proportionalGain(double bandwidth) const;
  double integralGain(double bandwidth) const;
};

/// What the loops command until their next update.
struct LoopCommand {
  WaveFrameForce force;           ///< a_v (energy), n_d (quadrature), n_v (precession); a_d = 0
  double reference_offset = 0.0;  ///< dw_r, rad/s
};

class ControlLoops {
 public:
  /// Throws std::invalid_argument if the settings do not validate.
  explicit ControlLoops(const LoopSettings& settings);

  const LoopSettings& settings() const { return settings_; }

  /// One update from the measured wave, `virtual_rate` the commanded electrical rate (rad/s) and
  /// `period` (s) the time the command will be held. The wave must stand (A^2 > B^2).
  LoopCommand update(const WaveParameters& measured, double virtual_rate, double period);

  /// The loops' integrators: the steady efforts they have learned (what a gyro's loop monitors read).
  double energyIntegral() const { return energy_integral_; }
  double quadratureIntegral() const { return quadrature_integral_; }
  double phaseIntegral() const { return phase_integral_; }

 private:
  LoopSettings settings_;
  double kp_energy_, ki_energy_, kp_quadrature_, ki_quadrature_, kp_phase_, ki_phase_;
  double energy_integral_ = 0.0, quadrature_integral_ = 0.0, phase_integral_ = 0.0;
};

}  // namespace core
}  // namespace hrg_gyro
