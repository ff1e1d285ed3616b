// The field method: D(theta) refreshed on a still gyro, without a table. The precession loop turns
// the standing wave at a commanded virtual rate w_v, both ways, through full turns, while the case
// stands still; the wave then turns at
//   d theta/dt = G_v(theta) w_v + K(theta) Omega_s + D(theta)
// with G_v the drive's realised gain of the command and Omega_s the Earth rate about the sensitive
// axis. That is the dual-rate method's equation with the commanded virtual angle psi (the integral of
// w_v, reported on precession/state: PlateauSample::rotation_angle) in place of the table angle and
// G_v in place of K: the same increment regression (increment_regression.h) fits G_v(theta) and the still gyro's rate
// D(theta) + K(theta) Omega_s at once, exactly for any window, with the block-sandwich standard errors.
// Both directions separate the two, as two table rates separate K and D.
//
// What a still gyro cannot give: K. Without a real rotation nothing scales with a body rate, so K0
// and its harmonics are kept from the prior (a table calibration), and the Earth rate's share,
// K(theta) Omega_s with Omega_s from the prior's latitude, is taken off the measured rate to leave
// D(theta). D0 is therefore only as good as K0 Omega_s is known, and a case that turns at a constant
// rate throughout is indistinguishable from a bias (say so where the gyro is installed). A case that
// moves at all is seen as scatter beyond the wave-angle noise, which a gate bounds.
//
// Fed by the session (calibration_session.h) from the precession state stream in place of the
// turntable's: its plateaus are the segments of constant commanded rate; static ones (w_v = 0) are
// skipped. Memory is bounded by the regression's sums and the bins.
#pragma once

#include <vector>

#include "hrg_gyro/core/calibration/calibration_method_interface.h"
#include "hrg_gyro/core/calibration/increment_chains.h"
#include "hrg_gyro/core/estimation/increment_regression.h"
#include "hrg_gyro/core/estimation/rate_groups.h"

namespace hrg_gyro {
namespace core {

class FieldMethod : public CalibrationMethod {
 public:
  explicit FieldMethod(const CalibrationSettings& settings);
  CalibrationMethodKind kind() const override { return CalibrationMethodKind::kField; }
  void addSample(const PlateauSample& s) override;
  bool complete() const override;
  CalibrationProgress progress() const override;
  CalibrationOutcome finish(const GyroParameters& prior) const override;

 private:
  /// Swept time a theta bin needs at this virtual rate: a quarter of its chains' window.
  double minBinTime(double rate) const { return chains_.minBinTime(rate); }
  /// The longest-running group of each sign of the commanded rate (-1: none).
  void directionGroups(int* positive, int* negative) const;
  // The phases of finish(), in its order.
  /// The two directions' rates, turns and times, and their coverage and turns gates; returns the
  /// swept time a bin needs in both.
  double gateDirections(const RateGroup& positive, const RateGroup& negative, CalibrationOutcome* o) const;
  /// The fit into the report, and D: the still gyro's rate less K(theta) Omega_s.
  HarmonicFitResult driftFromFit(const IncrementFit& e, const GyroParameters& prior, CalibrationOutcome* o) const;
  /// The gates on the fit: condition, stillness, the realised gain, D's errors, the loops' lag, the trend.
  void gateFit(const IncrementFit& e, const HarmonicFitResult& d, CalibrationOutcome* o) const;
  /// The notes on what was kept, what D rests on, and the fit.
  void noteResult(const IncrementFit& e, const GyroParameters& prior, CalibrationOutcome* o) const;

  CalibrationSettings settings_;
  RateGroups groups_;
  IncrementRegression regression_;
  // The wave turns at about the commanded rate: one radian of theta per radian of psi.
  IncrementChains chains_;
  double frequency_sum_ = 0.0;  // of the samples' resonator frequency, for a frequency-dependent prior K
  std::uint64_t frequency_count_ = 0;
  std::uint64_t samples_ = 0;
};

}  // namespace core
}  // namespace hrg_gyro
