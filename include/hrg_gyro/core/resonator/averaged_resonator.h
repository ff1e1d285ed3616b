// The resonator's n = 2 mode pair in slow variables: the averaged equations of motion of a
// whole-angle gyro, written in the package's wave state (A, B, theta, tau) of wave_parameters.h.
// The simulator's older dynamics take K(theta) and D(theta) as given; here they follow from the
// shell's defects and from the forces its control loops apply (resonator_dynamics.h).
//
// The oscillator. With x and y the amplitudes of the cos 2phi and sin 2phi shapes (the rim deflection
// is x cos 2phi + y sin 2phi, which the cosine and sine pickoff channels read) and Omega the body rate
// about the sensitive axis (rad/s, REP-103 sign), per unit modal mass:
//   x'' + 2 K0 Omega y' + (2/tau_d) x' + h (c_d x' + s_d y') + w0^2 x + w0 Dw (c_w x + s_w y) = f_x
//   y'' - 2 K0 Omega x' + (2/tau_d) y' + h (s_d x' - c_d y') + w0^2 y + w0 Dw (s_w x - c_w y) = f_y
// with the mean damping time tau_d, the damping anisotropy h = D(1/tau_d) along theta_d and the split
// Dw along theta_omega (shell_parameters.h), c_d, s_d = cos, sin 2 theta_d and c_w, s_w = cos, sin
// 2 theta_omega.
// Terms in Omega^2 and dOmega/dt (relative size Omega / w0) are left out. The gyroscopic term is
// written with K0 = -2k, which makes an ideal shell's wave turn at d theta/dt = K0 Omega.
//
// The slow variables. On the reference carrier w_r = w0 + dw_r (the phase loop's frequency),
//   x = A cos th cos(w_r t + tau) - B sin th sin(w_r t + tau)
//   y = A sin th cos(w_r t + tau) + B cos th sin(w_r t + tau)
// which is the package's standing wave r(t, phi) exactly (theta electrical). A force on the carrier,
// f_x = Re(F_x e^(i w_r t)) and likewise f_y, acts on the wave through its four components in the
// wave's own frame (WaveFrameForce): along the antinode (cos th, sin th) and the node (-sin th, cos th),
// each in phase with the displacement or with the velocity of the main wave.
//
// Averaging over one period (first order in the small rates / w0) gives, with
// E = A^2 + B^2, W = A^2 - B^2, d_d = 2 (theta - theta_d), d_w = 2 (theta - theta_omega):
//   dA/dt   = -A/tau_d - (h/2) A cos d_d - (Dw/2) B sin d_w + a_v
//   dB/dt   = -B/tau_d + (h/2) B cos d_d + (Dw/2) A sin d_w + n_d
//   dth/dt  = K0 Omega + [ (h/2) E sin d_d - Dw A B cos d_w + A n_v - B a_d ] / W
//   dtau/dt = -dw_r    + [ -h A B sin d_d + (Dw/2) E cos d_w + A a_d - B n_v ] / W
// with (a_v, a_d, n_v, n_d) the force's wave-frame components (1/s times amplitude units). So:
// damping anisotropy turns the wave towards the less damped axis at (h/2) sin d_d (the package's
// D(theta) sign: it adds to d theta/dt); a frequency split feeds quadrature, B, which then turns the
// wave (-Dw B/A cos d_w); a force at the antinode in phase with the velocity pumps A, one at the node
// in phase with the displacement builds B, one at the node in phase with the velocity turns the wave.
// The equations hold while the wave stands (W > 0): at A^2 = B^2 the wave travels and theta is
// undefined.
#pragma once

#include "hrg_gyro/core/model/wave_parameters.h"
#include "hrg_gyro/core/resonator/shell_parameters.h"

namespace hrg_gyro {
namespace core {

/// A force on the two mode coordinates per unit modal mass, as complex amplitudes on the reference
/// carrier: f_x(t) = x_re cos(w_r t) - x_im sin(w_r t), likewise f_y (amplitude units / s^2).
struct ModalForce {
  double x_re = 0.0, x_im = 0.0;
  double y_re = 0.0, y_im = 0.0;
};

/// A force as the wave sees it, in 1/s times amplitude units: what each component would add to the
/// slow variables of a wave without quadrature.
struct WaveFrameForce {
  double antinode_velocity = 0.0;      ///< a_v: along the antinode, in phase with the velocity: dA/dt
  double antinode_displacement = 0.0;  ///< a_d: along the antinode, in phase with the displacement: A dtau/dt
  double node_velocity = 0.0;          ///< n_v: along the node, in phase with the velocity: A dtheta/dt
  double node_displacement = 0.0;      ///< n_d: along the node, in phase with the displacement: dB/dt
};

/// Time derivatives of (A, B, theta, tau).
struct WaveRates {
  double amplitude = 0.0;   ///< dA/dt, amplitude units / s
  double quadrature = 0.0;  ///< dB/dt, amplitude units / s
  double theta = 0.0;       ///< dtheta/dt, electrical rad/s
  double phase = 0.0;       ///< dtau/dt, rad/s
};

/// The wave-frame components of a modal force on a wave at (theta, tau), exact for the averaged
/// model; cos_/sin_ are those of theta and tau, w0 in rad/s.
WaveFrameForce toWaveFrame(const ModalForce& force, double cos_theta, double sin_theta, double cos_tau, double sin_tau,
                           double w0);
/// The modal force whose wave-frame components on a wave at (theta, tau) are `force`: the inverse
/// of toWaveFrame (how a controller puts a wave-frame command onto the x and y electrodes).
ModalForce toModalForce(const WaveFrameForce& force, double cos_theta, double sin_theta, double cos_tau, double sin_tau,
                        double w0);

class AveragedResonator {
 public:
  /// Throws std::invalid_argument if the parameters do not validate.
  explicit AveragedResonator(const ShellParameters& parameters);

  const ShellParameters& parameters() const { return parameters_; }

  /// The averaged equations at `wave`, for body rate `body_rate` (rad/s), a force fixed on the
  /// electrodes and the reference carrier's offset dw_r = w_r - w0 (rad/s). `angle_rate` (rad/s) is
  /// added to dtheta/dt as it is: effects outside this model, e.g. a simulated turn-on bias.
  WaveRates rates(const WaveParameters& wave, double body_rate, const ModalForce& force, double reference_offset,
                  double angle_rate = 0.0) const;
  /// The same for a force given in the wave's frame, with cos 2theta and sin 2theta of the wave
  /// supplied (a force that follows the wave: what the loops' modulator applies).
  WaveRates rates(const WaveParameters& wave, double cos_2theta, double sin_2theta, double body_rate,
                  const WaveFrameForce& force, double reference_offset, double angle_rate = 0.0) const;

 private:
  ShellParameters parameters_;
  double w0_, inverse_damping_time_, half_h_, half_dw_, k0_;
  double cos_damping_axis_, sin_damping_axis_;      // of 2 theta_d
  double cos_frequency_axis_, sin_frequency_axis_;  // of 2 theta_omega
};

}  // namespace core
}  // namespace hrg_gyro
