// The drive chain between the control loops and the shell, with the imperfections a field
// calibration has to find. The loops ask for a force in the wave's frame (WaveFrameForce); the chain
// places it on the x and y forcer electrodes with the wave angle and phase the loops measured, and
// the electrodes realise it imperfectly:
//   - a relative gain error per electrode family, gc on the x (cos 2phi) and gs on the y (sin 2phi)
//     forcers. Their mean scales every loop's force; their half-difference (gc - gs)/2 rotates part
//     of the antinode force onto the node, so the amplitude loop's effort against damping leaks
//     into precession (a drift in sin 2 theta), and the precession force realised varies as
//     cos 2 theta;
//   - a phase lag of the realised force behind the commanded one (both families), which turns the
//     quadrature loop's effort against a frequency split into precession (a drift along the split's
//     axis) and the precession force partly into quadrature;
//   - a scale error of the precession (virtual rotation) channel alone: a reference or converter
//     error between the rate commanded and the force applied.
// The loops close around the first two for their own quantities (energy, quadrature); the virtual
// rate is open loop, so its realised gain is what a calibration of the precession drive estimates.
#pragma once

#include "hrg_gyro/core/resonator/averaged_resonator.h"

namespace hrg_gyro {
namespace core {

struct DriveChainErrors {
  double gain_error_c = 0.0;             ///< relative gain error of the x (cos 2phi) forcers
  double gain_error_s = 0.0;             ///< relative gain error of the y (sin 2phi) forcers
  double phase_error = 0.0;              ///< rad by which every realised force lags its command on the carrier
  double virtual_rate_gain_error = 0.0;  ///< relative scale error of the precession command alone

  /// Throws std::invalid_argument naming the field: all finite, gains > -1, |phase| < pi/2.
  void validate() const;
};

class DriveChain {
 public:
  /// Throws std::invalid_argument if the errors do not validate.
  explicit DriveChain(const DriveChainErrors& errors);

  const DriveChainErrors& errors() const { return errors_; }

  /// The modal force realised for a wave-frame command the loops placed with their measured
  /// (theta, tau) (given by cos and sin); w0 in rad/s. The command's node_velocity is the
  /// precession command.
  ModalForce realise(const WaveFrameForce& command, double cos_theta, double sin_theta, double cos_tau, double sin_tau,
                     double w0) const;
  /// What the wave receives of a command placed with its own angle and phase, given cos 2theta and
  /// sin 2theta: toWaveFrame(realise(...)) in closed form. With p, q = 1 + g +- gamma cos 2theta and
  /// r = gamma sin 2theta, the forcers map (alpha, beta) = (a_v + i a_d, n_v - i n_d) to
  /// e^(-i phi) (p alpha - r beta, -r alpha + q beta).
  WaveFrameForce onWave(const WaveFrameForce& command, double cos_2theta, double sin_2theta) const {
    const double alpha_re = command.antinode_velocity, alpha_im = command.antinode_displacement;
    const double beta_re = precession_scale_ * command.node_velocity, beta_im = -command.node_displacement;
    const double p = mean_ + half_difference_ * cos_2theta, q = mean_ - half_difference_ * cos_2theta;
    const double r = half_difference_ * sin_2theta;
    const double a_re = p * alpha_re - r * beta_re, a_im = p * alpha_im - r * beta_im;
    const double b_re = q * beta_re - r * alpha_re, b_im = q * beta_im - r * alpha_im;
    const double c = cos_phase_, s = sin_phase_;  // times c - i s
    WaveFrameForce f;
    f.antinode_velocity = c * a_re + s * a_im;
    f.antinode_displacement = c * a_im - s * a_re;
    f.node_velocity = c * b_re + s * b_im;
    f.node_displacement = -(c * b_im - s * b_re);
    return f;
  }

 private:
  DriveChainErrors errors_;
  double gain_c_, gain_s_;         // 1 + gc, 1 + gs
  double mean_, half_difference_;  // 1 + (gc + gs)/2, (gc - gs)/2
  double cos_phase_, sin_phase_;   // of the lag
  double precession_scale_;        // 1 + the precession channel's error
};

}  // namespace core
}  // namespace hrg_gyro
