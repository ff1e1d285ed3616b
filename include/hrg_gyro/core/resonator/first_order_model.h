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
#pragma once

#include "hrg_gyro/core/model/harmonic_model.h"
#include "hrg_gyro/core/resonator/control_loops.h"
#include "hrg_gyro/core/resonator/drive_chain.h"
#include "hrg_gyro/core/resonator/resonator_parameters.h"

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
ResonatorModel firstOrderModel(const ResonatorParameters& parameters, const LoopSettings& loops,
                               const DriveChainErrors& drive);

}  // namespace core
}  // namespace hrg_gyro
