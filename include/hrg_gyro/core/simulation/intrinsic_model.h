// What a simulated gyro's wave does at its true angle, as functions of theta: the scale factor
// K(theta), the drift D(theta) and, for the averaged resonator, the realised gain of the commanded
// virtual rate G_v(theta) (d theta/dt = K Omega + D + G_v w_v). These are the models a perfect
// calibration measures through the pickoffs (injected_model.h); the simulator's own dynamics are
// what they describe.
//
// The harmonic dynamics: K and D are the resonator section's models, and there is no precession
// loop (G_v = 0). The averaged resonator (dynamics.model: averaged): D is the settled drift exact to
// all orders in the drive chain's errors (SteadyStateResponse) plus the resonator section's drift,
// which adds to the shell's as a bias from outside the shell would; K is K0 with the quadrature
// loop's lag to first order (firstOrderModel: the only K(theta) the averaged shell has), and G_v the
// settled gain with that same lag.
#pragma once

#include <optional>

#include "hrg_gyro/core/model/harmonic_model.h"
#include "hrg_gyro/core/resonator/first_order_model.h"
#include "hrg_gyro/core/resonator/steady_state_response.h"
#include "hrg_gyro/core/simulation/simulation_config.h"

namespace hrg_gyro {
namespace core {

class IntrinsicModel {
 public:
  /// Thermal scenarios: the models at the nominal frequency (atTemperature() first for another).
  explicit IntrinsicModel(const SimulationConfig& config);

  bool averaged() const { return steady_.has_value(); }
  double scaleFactor(double theta) const;
  double drift(double theta) const;
  /// Realised over commanded virtual rate; 0 without a precession loop (harmonic dynamics).
  double virtualRateGain(double theta) const;
  /// The mean of D over theta, rad/s: the turn-on bias D0.
  double meanDrift() const { return mean_drift_; }

 private:
  double frequency_;
  HarmonicModel scale_factor_, added_drift_;
  std::optional<SteadyStateResponse> steady_;
  ResonatorModel first_order_;
  double k0_ = 0.0;  // the shell's K0 = -2k
  double mean_drift_ = 0.0;
};

}  // namespace core
}  // namespace hrg_gyro
