// The dual-rate method across temperature: K(theta, f) and D(theta, f) as splines over the
// resonator frequency f, their node values fitted directly from frequency-sliced binned rates.
//
// Why one joint fit instead of a dual-rate estimate per slice followed by a spline fit: the two
// table rates are rarely measured at exactly the same temperature, and D changing with f between
// them does not cancel in (r1 - r2) / (R1 - R2). Modelling every bin where its data were removes
// that: the bin of group g (effective rate R_g = table rate + Earth rate), slice s, theta bin b,
// with mean frequency f_b, measures
//   r = sum_j w_j(f_b) [ R_g (K0_j + sum_k a^K_kj <cos k theta>_b sinc^2(k L_gs/2) + b^K_kj <sin ..>)
//                          + (D0_j + ... the same with the D coefficients) ]
// which is linear in the node values (w_j the FrequencyInterpolator weights, <.>_b the bin's basis
// means, L_gs the window span of that group and slice, as in the dual-rate fit). Weighted least
// squares with the bins' data time as weights gives every node value at once; the standard errors
// use the same noise model as the dual-rate fit (telescoped bins: a covariance block per group and
// slice, sandwich form, significant excess scatter added as independent noise).
//
// The dual-rate pairing by theta bin is still computed, for the residual gate and the plots. On a
// ramp the two table rates are rarely seen in the same frequency slice, so each group's bins are
// first moved to the middle frequency of the nodes with the fitted frequency dependence and summed
// over the slices; then K = (r1 - r2) / (R1 - R2) and D = (r2 R1 - r1 R2) / (R1 - R2) per theta
// bin are the data at that frequency, and their scatter about the model seen the same way is the
// fit's residual. Both K and D are fitted over the union of their orders (as the dual-rate fit
// does) and reported at their own orders.
#pragma once

#include <string>
#include <vector>

#include "hrg_gyro/core/estimation/binned_rate_fit.h"
#include "hrg_gyro/core/estimation/harmonic_fit.h"
#include "hrg_gyro/core/estimation/rate_groups.h"
#include "hrg_gyro/core/model/frequency_interpolator.h"
#include "hrg_gyro/core/model/harmonic_model.h"

namespace hrg_gyro {
namespace core {

struct ThermalEstimate {
  bool ok = false;
  std::string reason;
  std::vector<HarmonicFitResult> k;      ///< one per node: K coefficients at the node, with standard errors
  std::vector<HarmonicFitResult> d;      ///< one per node, rad/s
  HarmonicModel k_model{0.0};            ///< K(theta, f) over the nodes
  HarmonicModel d_model{0.0};            ///< D(theta, f)
  double condition_number = 0.0;         ///< of the weighted design matrix with unit-norm columns
  double k_residual_rms = 0.0;           ///< rms of the binned K (at the middle frequency) about the fit
  double d_residual_rms = 0.0;           ///< rad/s
  std::size_t rows = 0;                  ///< bins used (all groups and slices)
  double smoothing_factor = 1.0;         ///< smallest window attenuation corrected for
  std::vector<BinnedCurvePoint> binned;  ///< per theta bin, moved to the middle frequency of the nodes
};

/// rate1, rate2: effective rates (table + Earth) of the two groups; bins with less than
/// min_bin_time s of data are left out. The fit refuses condition numbers above max_condition.
ThermalEstimate estimateThermal(const RateGroup& group1, double rate1, const RateGroup& group2, double rate2,
                                const FrequencyInterpolator& interpolator, int bins, const std::vector<int>& k_orders,
                                const std::vector<int>& d_orders, double min_bin_time, double max_condition);

}  // namespace core
}  // namespace hrg_gyro
