// What the resonator with its loops closed looks like to the package's calibration, to first order
// in the defects: D(theta) and K(theta) as the unified harmonic models (model/harmonic_model.h), and
// the realised gain of the virtual rate in the same form. These are what a perfect calibration of a
// gyro simulated with resonator_dynamics.h should find.
//
// With h = D(1/tau_d), Dw the split, g and gamma the mean and half-difference of the forcers' gain
// errors (gc, gs), phi the drive's phase lag and e_v the precession channel's scale error:
//   D(theta)   = (h/2) sin 2(theta - theta_d) + (Dw phi / 2) sin 2(theta - theta_omega) - (gamma/tau_d) sin 2theta
//     the damping anisotropy (towards the less damped axis); the quadrature loop's effort against the
//     split, turned into precession by the phase lag; the energy loop's effort against damping,
//     turned onto the node by the forcers' imbalance (absent without the energy loop). Only order 2.
//   K(theta)   = K0 [1 - L (1 + cos 4(theta - theta_omega))],  L = Dw^2 / (2 ki_q)
//     the quadrature loop's lag: a turning wave sweeps the split's quadrature source, the loop
//     leaves B = (d/dt of that source) / ki_q behind, and that B turns the wave back in proportion to
//     the rate (ki_q = (2 pi quadrature bandwidth)^2). First order in the rate over the loop's
//     bandwidth; the same factor scales the virtual rate.
//   G_v(theta) = 1 + e_v + g - L - gamma cos 2theta - L cos 4(theta - theta_omega)
// The neglected terms are products of two of the small numbers (g, gamma, phi, e_v, h tau_d, ...)
// times the first-order rates: steady_state_response.h gives the settled values exactly, and the
// largest difference over theta is the error of this model (tested).
//
// A wave precessed at a constant commanded rate w_v sweeps every defect at Omega = 2 w_v, and the
// loops, which cancel the defects' efforts at rest, trail them. What they leave behind turns the wave:
// the part odd in w_v scales with the command (G_v's lag above, to first order); the part even in
// w_v keeps its sign in both directions, so a field calibration (both ways at the same |w_v|, D the
// part the two share) reads it as drift. With Den = (ki - Omega^2)^2 + (kp Omega)^2, kp and ki the
// quadrature loop's (Den_q) or the energy loop's (Den_e), and h_c = 1 / control_rate, that part is
//   D_lag(theta) = - (Dw^2/4) kp Omega^2 / Den_q                        sin 4(theta - theta_omega)   (1)
//                  + (phi Dw/2) Omega^2 (ki - Omega^2) / Den_q            sin 2(theta - theta_omega)   (2)
//                  + (gamma^2 w_v/2) kp Omega^3 / Den_e                   sin 4theta                   (3)
//                  - gamma w_v^2 (h_c/2) Omega^2 (ki - Omega^2) / Den_e   sin 2theta                   (4)
//                  - w_v (h h_c/4) kp Omega^3 / Den_e                     sin 2(theta - theta_d)       (5)
// (1) B trails the split's source (the real part of s / (s^2 + kp s + ki)) and the split turns the
// wave with it; (2) the quadrature force trails the source (Re T - 1, T = (kp s + ki) / (s^2 + kp s +
// ki) the loop's closed-loop response) and the drive's lag turns it into precession; (3) the forcers'
// imbalance puts part of the precession force on the antinode, the energy loop's answer trails it
// (-Im T) and the imbalance puts it back on the node; (4), (5) the amplitude ripple the energy loop
// leaves, of (3)'s force and of the damping anisotropy, meets the precession force, which is
// normalised by the amplitude sampled at the start of each control period. Slow against the loops,
// (1) and (2) grow as w_v^2 (-(2 zeta Dw^2 / wq^3) w_v^2 and (2 phi Dw / wq^2) w_v^2, wq = 2 pi times
// the quadrature bandwidth), (3) to (5) as w_v^4. First order in each product shown (products such
// as gamma^2 h_c w_v^2 are left out: a few 1e-9 rad/s at 10 rad/s for the realistic gyro), exact in
// Omega over the loops' bandwidths with the loops taken as continuous (their sampling delay changes
// the terms by about 1 %): tested against resonator_dynamics.h from 0.2 to 10 rad/s.
#pragma once

#include "hrg_gyro/core/model/harmonic_model.h"
#include "hrg_gyro/core/resonator/control_loops.h"
#include "hrg_gyro/core/resonator/drive_chain.h"
#include "hrg_gyro/core/resonator/shell_parameters.h"

namespace hrg_gyro {
namespace core {

struct ResonatorModel {
  HarmonicModel drift;              ///< D(theta), rad/s: orders {2}
  HarmonicModel scale_factor;       ///< K(theta), electrical per body angle: orders {4}
  HarmonicModel virtual_rate_gain;  ///< G_v(theta), realised over commanded: orders {2, 4}
  double quadrature_lag = 0.0;      ///< L
};

/// Throws std::invalid_argument if a setting fails to validate, or if the quadrature loop is open
/// while there is a frequency split (B then grows and no drift settles).
ResonatorModel firstOrderModel(const ShellParameters& parameters, const LoopSettings& loops,
                               const DriveChainErrors& drive);

/// D_lag(theta) above, rad/s, orders {2, 4} and no mean, for a wave precessed at `virtual_rate`
/// (electrical rad/s, either sign: the result is even in it). Throws std::invalid_argument as
/// firstOrderModel does, and for a rate that is not finite.
HarmonicModel precessionLagDrift(const ShellParameters& parameters, const LoopSettings& loops,
                                 const DriveChainErrors& drive, double virtual_rate);

}  // namespace core
}  // namespace hrg_gyro
