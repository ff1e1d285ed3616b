// How fast the wave turns once the loops have settled, in closed form: the drift D(theta) of a wave
// held at theta and the gain of the virtual rate, exact for the averaged equations with the drive
// chain's errors to all orders, for a wave that stands still or turns slowly against the loops'
// bandwidths (their lag is first_order_model.h's K perturbation).
//
// Settled means B = 0 and dA/dt = 0: the quadrature loop's and the energy loop's integrators have
// found the forces that hold them. With p, q = 1 + g +- gamma cos 2th, r = gamma sin 2th (g, gamma the
// mean and half-difference of the forcers' gain errors), c, s = cos, sin of the drive's phase lag,
// rho = 1/tau_d + (h/2) cos d_d and sigma = (Dw/2) sin d_w the efforts the two loops must supply, those
// two conditions are linear in the loops' forces; solved, the force the node receives in phase with
// the velocity turns the wave at
//   D(theta)   = (h/2) sin d_d + [ sigma s c (p q - r^2) - rho r q ] / (c^2 p q + s^2 r^2)
//   G_v(theta) = (1 + e_v) c q (p q - r^2) / (c^2 p q + s^2 r^2)
// (d theta/dt = K0 Omega + D(theta) + G_v(theta) w_v). Without the energy loop (no force against the
// damping) D = (h/2) sin d_d + sigma s / c and G_v = (1 + e_v) q / c.
#pragma once

#include "hrg_gyro/core/resonator/control_loops.h"
#include "hrg_gyro/core/resonator/drive_chain.h"
#include "hrg_gyro/core/resonator/shell_parameters.h"

namespace hrg_gyro {
namespace core {

class SteadyStateResponse {
 public:
  /// Throws std::invalid_argument if a setting fails to validate, or if the quadrature loop is open
  /// (then B is not held and nothing settles).
  SteadyStateResponse(const ShellParameters& parameters, const LoopSettings& loops, const DriveChainErrors& drive);

  /// D(theta), rad/s: the settled wave's angle rate at zero body rate and no virtual rate.
  double drift(double theta) const;
  /// G_v(theta): realised over commanded virtual rate.
  double virtualRateGain(double theta) const;

 private:
  struct Terms {
    double p, q, r, rho, sigma, half_h_sin_dt;
  };
  Terms terms(double theta) const;

  ShellParameters parameters_;
  DriveChainErrors drive_;
  bool energy_loop_;
  double c_, s_;
};

}  // namespace core
}  // namespace hrg_gyro
