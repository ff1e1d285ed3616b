// The thermal calibration method ("thermal"): the dual-rate method across temperature.
//
// Why: the resonator frequency f tracks temperature, and K and D drift with it; a model calibrated
// at one temperature leaves ppm-level nonlinearity and scale-factor errors at another. This method
// takes dual-rate plateaus recorded while the temperature moves (a ramp, or soaks at several
// temperatures), bins theta per frequency slice (RateGroups with a slice width) and fits every coefficient
// of K and D as a spline over f (ThermalEstimate). The written parameter file carries
// frequency_nodes, and the processor evaluates K and D at each sample's frequency.
//
// Nodes: thermal/frequency_nodes, or thermal/node_count nodes spread evenly over the frequencies
// seen. Samples without a frequency, outside explicit nodes, or beyond the slice limit are counted
// and left out. Quality gates: those of the dual-rate method (samples, two rate groups, rate
// separation and noise, fit conditioning, K0 sign and change at every node, residual of the binned
// K moved to the middle frequency, largest K-harmonic standard error at any node) plus the
// coverage of theta at both rates in every node interval and node intervals at least one slice
// wide.
#pragma once

#include <limits>
#include <vector>

#include "hrg_gyro/core/calibration/calibration_method_interface.h"
#include "hrg_gyro/core/estimation/rate_groups.h"
#include "hrg_gyro/core/estimation/thermal_estimator.h"

namespace hrg_gyro {
namespace core {

class ThermalMethod : public CalibrationMethod {
 public:
  /// k0: the prior's mean scale factor (the angle rate per table rate, for the window length).
  ThermalMethod(const CalibrationSettings& settings, double k0);
  CalibrationMethodKind kind() const override { return CalibrationMethodKind::kThermal; }
  void addSample(const PlateauSample& s) override;
  bool complete() const override;
  CalibrationProgress progress() const override;
  CalibrationOutcome finish(const GyroParameters& prior) const override;

 private:
  double minBinTime() const { return 0.25 * settings_.window; }
  /// The explicit nodes, or node_count nodes evenly over the frequencies seen (empty if none).
  std::vector<double> nodes() const;
  /// Per node interval: fraction of theta bins the group swept for at least minBinTime().
  std::vector<double> intervalCoverage(const RateGroup& group, const std::vector<double>& nodes) const;
  /// Smallest coverage over the intervals and the two main groups; `worst` gets the interval.
  double worstCoverage(const std::vector<double>& nodes, std::size_t* worst) const;

  // The phases of finish(), in its order.
  /// One summary per rate group, most data first.
  void summarizeGroups(CalibrationOutcome* o) const;
  /// Notes on the samples left out (no frequency, outside the nodes, beyond the slice limit).
  void noteDroppedSamples(CalibrationOutcome* o) const;
  /// Gates on the data of the two main groups g1, g2 at the nodes n: node spacing, coverage, rate
  /// separation and noise.
  void gateData(const std::vector<double>& n, const RateGroup& g1, const RateGroup& g2, CalibrationOutcome* o) const;
  /// Gates on the fit at every node (K0 sign and change, residual, harmonic standard error) and the
  /// peak nonlinearity; returns the steepest node's K slope for the error bound.
  double gateNodes(const std::vector<double>& n, const ThermalEstimate& e, const GyroParameters& prior,
                   CalibrationOutcome* o) const;
  /// The paper-style error bound of the window method with the steepest node's model.
  double errorBound(double slope, const RateGroup& g1, const RateGroup& g2) const;

  CalibrationSettings settings_;
  RateGroups rates_;
  std::uint64_t samples_ = 0, no_frequency_ = 0, out_of_range_ = 0, slice_limit_ = 0;
  double f_min_ = std::numeric_limits<double>::infinity(), f_max_ = -std::numeric_limits<double>::infinity();
};

}  // namespace core
}  // namespace hrg_gyro
