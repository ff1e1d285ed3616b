// What the increment regression (increment_regression.h) returns: K(theta) and D(theta) with the
// parts of their standard errors, the bias trend and random walk fitted with them, the horizontal
// Earth rate of each fixture position, and the binned curves the report shows. Plain results, in a
// header of their own so that the methods and the outcome that carry them need not see how they
// are estimated.
#pragma once

#include <string>
#include <vector>

#include "hrg_gyro/core/common/units.h"
#include "hrg_gyro/core/estimation/binned_rate_fit.h"
#include "hrg_gyro/core/estimation/harmonic_fit.h"

namespace hrg_gyro {
namespace core {

/// What the reported standard error of each K term is made of (term order: mean, cos..., sin...).
struct IncrementErrorBudget {
  std::vector<double> statistical;   ///< from the data: block sandwich, never below the white-noise prediction
  std::vector<double> angle_noise;   ///< predicted by the white wave-angle noise alone
  std::vector<double> beyond_noise;  ///< statistical beyond that: table angle/rate errors, rate noise, drift
  std::vector<double> earth_rate;    ///< from the Earth-rate uncertainty
  std::vector<double> basis_noise;   ///< from the uncertainty of the basis-noise correction
  std::vector<double> bias_walk;     ///< predicted by the estimated bias random walk (0: none carried)
};

/// The bias random walk estimated from the residuals of the increment fit.
struct BiasWalkFit {
  double rate_random_walk = 0.0;      ///< q, rad/s/sqrt(s) (0 where the estimate is negative)
  double rate_random_walk_std = 0.0;  ///< standard error of q
  double angle_random_walk = 0.0;     ///< N, rad/sqrt(s), fitted with it
  bool carried = false;               ///< q^2 > 0: the covariance carries the walk
};

/// The Earth's horizontal rate that one fixture position's tilt lets into the axis: the coefficients
/// of cos psi and sin psi (psi the heading of the platter's x), rad/s.
struct HorizontalEarthFit {
  int slot = 0;
  double cos = 0.0, sin = 0.0;
  double cos_std = 0.0, sin_std = 0.0;
};

/// The bias trend fitted with K and D (bias_trend_order > 0).
struct BiasTrendFit {
  int order = 0;
  std::vector<double> coefficients;  ///< b_j, rad/s per s^j
  std::vector<double> stds;          ///< their standard errors
  double reference_time = 0.0;       ///< s from the first sample: t_ref, where D0 is the bias
  Nanoseconds reference_stamp = 0;   ///< the same as a stamp
  double span = 0.0;                 ///< s from the first to the last sample fitted
  /// K0's statistical standard error with the trend fitted over that without it (>= 1), and the
  /// correlation of K0 with the linear coefficient: how much the session confuses the two.
  double k0_inflation = 1.0;
  double k0_correlation = 0.0;
};

struct IncrementFit {
  bool ok = false;
  std::string reason;
  HarmonicFitResult k;  ///< K(theta), standard errors include the systematic terms of `budget`
  HarmonicFitResult d;  ///< D(theta), rad/s
  IncrementErrorBudget budget;
  IncrementErrorBudget drift_budget;     ///< the same for the D terms (mean, cos..., sin...)
  std::vector<BinnedCurvePoint> binned;  ///< fitted model plus the binned residual of the two main groups
  double angle_noise = 0.0;              ///< estimated white wave-angle noise per sample, rad
  double mean_window = 0.0;              ///< s between consecutive window means
  std::size_t increments = 0;
  std::size_t blocks = 0;                      ///< blocks of the sandwich covariance
  BiasTrendFit trend;                          ///< order 0: none fitted
  BiasWalkFit walk;                            ///< the bias's random walk, estimated whatever the trend order
  std::vector<HorizontalEarthFit> horizontal;  ///< per horizontal slot with data, in slot order
  /// Weight of the logged table angle against the integral of the logged rate (with the angle's
  /// slope per chain), time-weighted over the chains: 1 the angle alone, 0 the rate's shape alone.
  double angle_weight = 1.0;
};

}  // namespace core
}  // namespace hrg_gyro
