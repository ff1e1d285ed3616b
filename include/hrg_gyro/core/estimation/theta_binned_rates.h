// Rates accumulated by wave-angle bin over one plateau group, in O(bins) memory.
//
// The samples (t, theta, y) of a plateau are first averaged over windows of `window` seconds (the
// paper's tau), which cuts the angle noise by sqrt(samples per window). Consecutive window means
// give increments (dy, dt) that are added to the bin of their midpoint angle (theta modulo pi). A
// bin's rate is sum dy / sum dt; within one pass the increments telescope, so the noise of a bin
// rate is that of the two window means at its edges, and neighbouring bins share (and cancel) that
// noise in a harmonic fit. With y = theta this measures d theta/dt for calibration; with y = the
// compensated angle it measures the output rate for verification.
//
// Where in the bin: increments land in a bin whole, about one or two per pass, so the angles a bin
// really averages over jitter by half a window around its centre. Each bin therefore also keeps the
// dt-weighted mean of cos(k theta) and sin(k theta) at its increments' midpoints (orders 2, 4, ...,
// max_order); a fit on those means is exactly the fit on every increment, with no bin-width or
// jitter error. The window-to-window difference still averages harmonic k by sinc^2(k L / 2), L the
// angle swept in one window (windowSpan()); the fit corrects that factor.
//
// A sample may carry a tag (the resonator frequency, for the thermal calibration): each bin keeps
// the dt-weighted mean tag of its increments, so a model that depends on the tag can be evaluated
// where the bin's data really were.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <map>
#include <utility>
#include <vector>

#include "hrg_gyro/core/common/units.h"
#include "hrg_gyro/core/model/harmonic_basis.h"

namespace hrg_gyro {
namespace core {

class ThetaBinnedRates {
 public:
  /// max_order: highest (even) harmonic order whose basis means are kept.
  ThetaBinnedRates(int bins, double window_seconds, int max_order);

  /// Adds one sample of the plateau (stamps increasing within a chain); `tag` is averaged per bin.
  void add(Nanoseconds stamp, double theta, double y, double tag = 0.0);
  /// The next sample starts a new chain: no increment spans a plateau change or a gap.
  void breakChain();

  int binCount() const { return static_cast<int>(bins_.size()); }
  double binWidth() const { return kPi / binCount(); }
  double binCenter(int b) const { return (b + 0.5) * binWidth(); }
  double binTime(int b) const { return bins_[b].dt; }
  /// sum dy / sum dt of the bin (0 when the bin is empty; check binTime()).
  double binRate(int b) const { return bins_[b].dt > 0.0 ? bins_[b].dy / bins_[b].dt : 0.0; }
  /// dt-weighted mean tag of the bin's increments (0 when the bin is empty).
  double binTag(int b) const { return bins_[b].dt > 0.0 ? bins_[b].tag / bins_[b].dt : 0.0; }
  /// s of increments whose angle span overlapped the bin (what coverage() counts).
  double binSwept(int b) const { return bins_[b].swept; }
  int maxOrder() const { return max_order_; }
  /// dt-weighted mean of cos(k theta) (or sin) over the bin's increment midpoints; k even <= maxOrder().
  double basisMean(int b, int k, bool sine) const {
    return bins_[b].dt > 0.0 ? basis_[b * 2 * (max_order_ / 2) + 2 * (k / 2 - 1) + (sine ? 1 : 0)] / bins_[b].dt : 0.0;
  }
  /// Fraction of bins whose angle the increments swept for at least min_time seconds (an increment
  /// spreads its time over the bins its angle span overlaps; with long windows one increment spans
  /// several bins, so counting midpoints would understate the coverage).
  double coverage(double min_time) const;

  std::uint64_t samples() const { return samples_; }
  double totalTime() const { return total_time_; }
  /// Electrical angle swept by the increments, rad.
  double thetaSwept() const { return theta_swept_; }
  /// Mean |d theta / dt| over the increments, rad/s.
  double meanThetaRate() const { return total_time_ > 0.0 ? theta_swept_ / total_time_ : 0.0; }
  /// Mean spacing of consecutive window means, s (the effective window).
  double effectiveWindow() const { return increments_ > 0 ? total_time_ / increments_ : 0.0; }
  /// Angle swept in one effective window, rad: the window smoothing acts as sinc^2(k span / 2).
  double windowSpan() const { return meanThetaRate() * effectiveWindow(); }
  /// Noise of y per input sample (white-noise estimate from each sample's deviation from the line
  /// through its neighbours; valid for uneven spacing).
  double sampleNoise() const;
  /// Noise of one window mean of y.
  double windowNoise() const;
  /// Covariance of the bin rates of `bins` due to the window-mean noise: a bin rate is
  /// (sum of its telescoped window-mean differences) / time, so it carries two window-mean errors per
  /// run of increments through it, and shares (with opposite sign) the one at each boundary it has
  /// with the next run in another bin.
  Eigen::MatrixXd rateCovariance(const std::vector<int>& bins) const;

 private:
  struct Bin {
    double dy = 0.0;
    double dt = 0.0;
    std::uint32_t runs = 0;         // maximal runs of consecutive increments in this bin
    std::uint32_t shared_next = 0;  // window means shared with bin (b + 1) mod n
    double swept = 0.0;             // s of increments whose angle span overlaps the bin
    double tag = 0.0;               // sum dt tag
  };
  struct Block {
    Nanoseconds start = 0;
    double t_sum = 0.0, theta_sum = 0.0, y_sum = 0.0, tag_sum = 0.0;
    std::uint64_t n = 0;
  };

  void closeBlock();
  void sweep(double lo, double hi, double dt);

  std::vector<Bin> bins_;
  int max_order_;
  std::vector<double> basis_;  // per bin: sum dt cos(k th), sum dt sin(k th) for k = 2, 4, ...
  Nanoseconds window_ns_;
  bool has_origin_ = false;
  Nanoseconds origin_ = 0;
  Block block_;
  bool has_previous_mean_ = false;
  double previous_t_ = 0.0, previous_theta_ = 0.0, previous_y_ = 0.0, previous_tag_ = 0.0;
  int previous_bin_ = -1;                                    // bin of the last increment of the chain
  std::map<std::pair<int, int>, std::uint32_t> shared_far_;  // rare: boundaries between non-adjacent bins
  std::uint64_t samples_ = 0, increments_ = 0, window_samples_ = 0;
  double total_time_ = 0.0, theta_swept_ = 0.0;
  // The last two samples, for the noise estimate.
  int history_ = 0;
  double y1_ = 0.0, y2_ = 0.0;
  Nanoseconds t1_ = 0, t2_ = 0;
  double d2_sum_ = 0.0;
  std::uint64_t d2_n_ = 0;
  HarmonicBasis basis_eval_;
};

}  // namespace core
}  // namespace hrg_gyro
