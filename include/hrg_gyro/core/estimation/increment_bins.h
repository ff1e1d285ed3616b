// The increment regression's per-bin sums and the binned K(theta) and D(theta) the report shows.
//
// Per wave-angle bin over [0, pi) and plateau group the increments' sums are kept; once fitted, the
// two groups with the most data give each bin's mean residual rate, separated into K and D by the
// two groups' rates, and added to the fitted model at the bin's centre: the curve shows what the
// harmonics leave, and its rms about the model is the fits' residual.
#pragma once

#include <Eigen/Core>
#include <map>
#include <vector>

#include "hrg_gyro/core/estimation/binned_rate_fit.h"
#include "hrg_gyro/core/estimation/harmonic_fit.h"
#include "hrg_gyro/core/estimation/window_chains.h"

namespace hrg_gyro {
namespace core {

/// The binned curves and the residual rms of K and D about the fitted models.
struct IncrementBinnedCurves {
  std::vector<BinnedCurvePoint> points;
  double k_residual_rms = 0.0, d_residual_rms = 0.0;
};

class IncrementBins {
 public:
  /// bins over [0, pi), positive; columns: the model's (IncrementModel::columns()).
  IncrementBins(int bins, int columns);

  /// The increment into its group's bin of its mid wave angle.
  void add(const WindowIncrement& increment);
  /// The bin of wave angle theta (folded into [0, pi)).
  int binOf(double theta) const;

  /// The curves of the two groups with the most data: the fitted columns `sel` with coefficients
  /// `beta` (sums mapped by `map`), the models k and d, the Earth rate added to the table's; bins
  /// with less than min_bin_time s in either group are left out.
  IncrementBinnedCurves curves(const std::vector<int>& sel, const Eigen::VectorXd& beta, const Eigen::MatrixXd& map,
                               const HarmonicModel& k, const HarmonicModel& d, double earth_rate,
                               double min_bin_time) const;

 private:
  struct BinSums {
    Eigen::VectorXd w;  // sum of the increments' w
    double dt = 0.0, dphi = 0.0;
  };

  int bins_, m_;
  std::map<int, std::vector<BinSums>> bins_by_group_;
  std::map<int, double> group_time_;
};

}  // namespace core
}  // namespace hrg_gyro
