// The K(theta) and D(theta) a perfect calibration should find for a simulated gyro.
//
// The processor measures theta~ = g(theta) through the pickoffs (and the correction P it applies),
// so what it sees is d theta~ = g'(theta) [K(theta) (d alpha + Omega_E dt) + D(theta) dt]: the
// effective models are K_eff(theta~) = g' K and D_eff(theta~) = g' D. g is measured noise free at
// signal level on a fine grid of true angles, g' by five-point central differences, and both effective models
// are fitted with harmonics of theta~. This is the "injected" reference of the summaries and tests.
// K and D at the true angle are intrinsic_model.h's: the given models, or those the averaged
// resonator settles to. With the averaged resonator the realised gain of the virtual rate is
// measured the same way: G_v,eff(theta~) = g' G_v (what the field calibration estimates).
#pragma once

#include <vector>

#include "hrg_gyro/core/estimation/harmonic_fit.h"
#include "hrg_gyro/core/model/correction_matrix.h"
#include "hrg_gyro/core/simulation/simulation_config.h"

namespace hrg_gyro {
namespace core {

struct EffectiveModel {
  HarmonicFitResult scale_factor;  ///< K_eff over the requested orders
  HarmonicFitResult drift;         ///< D_eff, rad/s
  double nonlinearity_ppm = 0.0;   ///< peak |K_eff - K0| / |K0| including every order up to 16
  /// G_v,eff over the requested orders (computeEffectiveModel with gain orders; averaged resonator
  /// only, else not ok).
  HarmonicFitResult virtual_rate_gain;
};

/// The injected turn-on bias D0(t) of a scenario at t s from its start, rad/s, without the random
/// walk: the mean of the intrinsic D (at the temperature of time t) plus the bias drift's trend. The
/// random walk's realisation is a draw of the run: the ground truth carries it (TruthState::bias).
double injectedBiasTrend(const SimulationConfig& config, double t);

/// `gain_orders`: those of G_v,eff, fitted only for the averaged resonator (empty: not fitted).
EffectiveModel computeEffectiveModel(const SimulationConfig& config, const CorrectionMatrix& correction,
                                     const std::vector<int>& k_orders, const std::vector<int>& d_orders,
                                     const std::vector<int>& gain_orders = {});

}  // namespace core
}  // namespace hrg_gyro
