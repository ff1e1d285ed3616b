// The shell of a hemispherical resonator as the averaged equations see it: the mean frequency and
// damping of its n = 2 wineglass pair, the Coriolis coupling (Bryan factor) and the two defects that
// make the pair anisotropic, a frequency split and a damping anisotropy, each along its own axis.
//
// Axes are given as **electrical** angles, like the wave angle theta: a mode whose antinode sits at
// case angle phi has electrical angle 2 phi. The two modes of the pair along one defect's axes are
// then pi/2 apart electrically (45 degrees on the shell). Rates are rad/s, times s.
//
// Not the simulation's `resonator` section (ResonatorConfig, simulation_config.h: the simulated gyro's
// sampling, wave and given K and D); a scenario gives these in its `dynamics.shell` section.
#pragma once

namespace hrg_gyro {
namespace core {

struct ShellParameters {
  double frequency = 5000.0;  ///< f0, Hz: the mean resonance of the pair (w0 = 2 pi f0)
  /// k, the Bryan factor: relative to the case the wave turns by -k times the body angle on the
  /// shell, so the package's scale factor is K0 = -2 k in electrical angle.
  double bryan_factor = 0.28;
  /// tau_d, s: the mean decay time constant of the amplitude, 1/tau_d = (1/tau_d1 + 1/tau_d2) / 2
  /// (Q = pi f0 tau_d). Not the temporal phase tau of the wave.
  double damping_time = 600.0;
  /// h = D(1/tau_d) = 1/tau_d1 - 1/tau_d2, 1/s: the mode along damping_axis decays at 1/tau_d1, the one
  /// at damping_axis + pi/2 (electrical) at 1/tau_d2.
  double damping_anisotropy = 0.0;
  double damping_axis = 0.0;  ///< theta_d, electrical rad
  /// Delta omega = w1 - w2, rad/s: the mode along frequency_axis rings at w1 = w0 + Delta omega / 2,
  /// the one at frequency_axis + pi/2 (electrical) at w2 = w0 - Delta omega / 2.
  double frequency_split = 0.0;
  double frequency_axis = 0.0;  ///< theta_omega, electrical rad

  /// K0 = -2 k, electrical angle per body angle.
  double scaleFactor() const { return -2.0 * bryan_factor; }
  double angularFrequency() const;
  /// Throws std::invalid_argument naming the field: f0 > 0, 0 < k < 1, tau_d > 0, every value
  /// finite, and |h| < 2/tau_d (both modes damped).
  void validate() const;
};

}  // namespace core
}  // namespace hrg_gyro
