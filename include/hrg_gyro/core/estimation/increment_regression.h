// K(theta) and D(theta) fitted to window increments of the wave angle, exact
// for any window and any sweep, however non-uniform: the facade the dual-rate
// and field methods use.
//
// The session's samples go chain by chain into window means (window_chains.h),
// each sample adding its trapezoid to the integrals of the increment model
// (increment_model.h), with the wave angle's noise estimated on the way
// (wave_angle_noise.h). Each window increment is handed to the parts that keep
// the session's sums: the blocks of the sandwich covariance
// (increment_blocks.h), the prefix sums of the bias random walk
// (bias_random_walk.h) and the per-bin sums of the report's curves
// (increment_bins.h). solve() fits the model to them and returns an
// IncrementFit (increment_fit.h): K and D with their error budgets, the bias
// trend and walk, the horizontal Earth rate per fixture position, the binned
// curves.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <cstddef>
#include <vector>

#include "hrg_gyro/core/common/units.h"
#include "hrg_gyro/core/estimation/bias_random_walk.h"
#include "hrg_gyro/core/estimation/increment_bins.h"
#include "hrg_gyro/core/estimation/increment_blocks.h"
#include "hrg_gyro/core/estimation/increment_fit.h"
#include "hrg_gyro/core/estimation/increment_model.h"
#include "hrg_gyro/core/estimation/window_chains.h"

namespace hrg_gyro {
namespace core {

class IncrementRegression {
 public:
  /// Orders must be positive. bins: wave-angle bins over [0, pi) for the binned
  /// curves. bias_trend_order: degree of the bias's polynomial in time (0: a
  /// constant bias; at most 2). horizontal_slots: fixture positions whose
  /// horizontal Earth rate is fitted (0: none).
  IncrementRegression(const std::vector<int>& k_orders, const std::vector<int>& d_orders, int bins,
                      int bias_trend_order = 0, int horizontal_slots = 0);

  /// Starts a chain of plateau group `group` averaged over windows of `window`
  /// s (ends any open chain).
  void startChain(int group, double window);
  /// Adds a sample of the open chain: theta the measured wave angle, phi the
  /// table angle (without the Earth rate, which solve() adds), phi_rate the
  /// integral of the table's logged rate from the chain's start (NaN: none);
  /// stamps increasing. horizontal_slot: the fixture position whose horizontal
  /// Earth rate the sample carries (-1: none), psi the heading of the platter's
  /// x, rad.
  void add(Nanoseconds stamp, double theta, double phi, double phi_rate = NAN, int horizontal_slot = -1,
           double psi = 0.0);
  /// Closes the open chain (its last, partial window is left out).
  void endChain();
  /// rad^2: an error of the angle that is smooth in time (regularised stamps),
  /// which the window means' scatter does not show; counted against the angle
  /// when the two sources are weighed.
  void setAngleSmoothError(double variance) { chains_.setAngleSmoothError(variance); }
  bool inChain() const { return chains_.inChain(); }
  int horizontalSlots() const { return model_.horizontalSlots(); }

  std::size_t increments() const { return increments_; }

  /// earth_rate: rad/s added to dphi/dt; earth_rate_std: its uncertainty
  /// (propagated to K). min_bin_time: s of increments a bin needs in both
  /// groups to be shown.
  IncrementFit solve(double earth_rate, double earth_rate_std, double min_bin_time, double max_condition) const;

 private:
  /// An increment of a chain that ended, to each part that keeps the session's
  /// sums.
  void addIncrement(const WindowIncrement& increment);
  /// The coefficients' covariances at the solution: the sandwich, the white
  /// floor, the walk's.
  IncrementCovariances covariances(const std::vector<IncrementBlock>& blocks, const std::vector<int>& sel,
                                   const Eigen::MatrixXd& map, const LeastSquaresSolution& solution, double angle_noise,
                                   BiasWalkFit* walk) const;
  /// The fitted terms into the fit's K, D, trend and horizontal Earth rate.
  void fillResults(const IncrementColumns& columns, const IncrementTerms& terms, const LeastSquaresSolution& solution,
                   const Eigen::MatrixXd& map, const Eigen::MatrixXd& total, double reference_time,
                   IncrementFit* fit) const;

  IncrementModel model_;
  WindowChains chains_;
  IncrementBlocks blocks_;
  BiasRandomWalk walk_;
  IncrementBins bins_;
  std::size_t increments_ = 0;
  double increment_time_ = 0.0;
  double increment_time_moment_ = 0.0;  // sum of increment dt x mean time: the trend's reference
};

}  // namespace core
}  // namespace hrg_gyro
