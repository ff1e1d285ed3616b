// Harmonic fits of theta-binned rates (ThetaBinnedRates): one plateau group's rate r(theta), and
// K(theta) and D(theta) from two groups by their difference, the estimate the verification makes of
// a processor's output against the truth (the dual-rate calibration itself fits window increments
// exactly: increment_regression.h).
//
// Each group g at effective rate R_g (table rate + Earth rate for calibration) measures, per wave
// angle bin, r_g(theta) = K(theta) R_g + D(theta). Per bin (pairing by theta, not by time):
//   K = (r1 - r2) / (R1 - R2),   D = (r2 R1 - r1 R2) / (R1 - R2)  [= r1 - K R1].
// The harmonic fit is done per group first, each with its own smoothing correction (bin width and
// window, which differ when |R1| != |R2|), and the coefficients are then combined with the same
// linear formulas; that removes the ~1e-6 residual that pairing the smoothed curves would leave for
// same-sign rates.
#pragma once

#include <string>
#include <vector>

#include "hrg_gyro/core/estimation/harmonic_fit.h"
#include "hrg_gyro/core/estimation/theta_binned_rates.h"

namespace hrg_gyro {
namespace core {

/// K and D at one wave-angle bin: the binned curves the reports draw against the fitted models.
struct BinnedCurvePoint {
  double theta = 0.0;   ///< bin centre, rad
  double k = 0.0;       ///< (r1 - r2) / (R1 - R2), smoothed by the bin and window
  double d = 0.0;       ///< rad/s
  double weight = 0.0;  ///< s of data (smaller of the two groups)
};

/// K(theta) and D(theta) from two groups' binned rates.
struct BinnedTwoRateFit {
  bool ok = false;
  std::string reason;
  HarmonicFitResult k;  ///< K(theta) with standard errors (residual of the binned K about the fit)
  HarmonicFitResult d;  ///< D(theta), same units as the rates
  HarmonicFitResult group_fit[2];
  std::vector<BinnedCurvePoint> binned;
  double smoothing_factor = 1.0;  ///< smallest attenuation corrected for
};

/// min_bin_time: bins with less data in either group are left out.
BinnedTwoRateFit fitBinnedTwoRates(const ThetaBinnedRates& group1, double rate1, const ThetaBinnedRates& group2,
                                   double rate2, const std::vector<int>& k_orders, const std::vector<int>& d_orders,
                                   double min_bin_time, double max_condition = 1e6);

/// Fits one group's binned rates (the constant-rate method's K, each group of fitBinnedTwoRates).
HarmonicFitResult fitBinnedRates(const ThetaBinnedRates& group, const std::vector<int>& orders, double min_bin_time,
                                 double max_condition = 1e6);

}  // namespace core
}  // namespace hrg_gyro
