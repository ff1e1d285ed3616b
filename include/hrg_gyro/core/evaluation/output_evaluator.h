// Measures what a processor output is worth against the simulator's ground truth.
//
// Scale-factor nonlinearity is measured the way a test engineer would on a rate table, by the
// dual-rate method applied to the output: on plateaus at two table rates, the compensated angle's
// rate is binned by wave angle and K_rel(theta) = (r1 - r2) / (R1 - R2) is fitted with harmonics,
// R the true inertial rates. Its peak deviation from the mean, relative to the mean, is the
// residual nonlinearity (ppm) with a 1-sigma figure from the fit; residual drift cancels. The
// angle error is the output angle minus the true inertial angle, both from the first sample,
// averaged over blocks of angle_error_window seconds (a single sample carries the white angle
// noise of the pickoff, ~2e-5 rad at 1 kHz, which would hide any systematic error).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "hrg_gyro/core/estimation/harmonic_fit.h"
#include "hrg_gyro/core/estimation/plateau_detector.h"
#include "hrg_gyro/core/estimation/rate_groups.h"

namespace hrg_gyro {
namespace core {

struct EvaluationSettings {
  int bins = 128;
  double window = 2.0;        ///< s, longest averaging window
  double window_span = 0.06;  ///< rad of wave angle per window at most (as the calibrator)
  double k0 = 0.56;           ///< |K0|, wave angle per body angle, for the window length
  std::vector<int> orders{2, 4, 6, 8, 10, 12};
  PlateauSettings plateau{2e-4, 2e-3, 1.0, 2e-4, 0.5};
  double group_tolerance = 1e-3;
  double angle_error_window = 1.0;  ///< s
};

struct EvaluationResult {
  bool ok = false;
  std::string reason;
  HarmonicFitResult relative_scale;     ///< K_rel(theta): output angle per true angle
  double nonlinearity_ppm = 0.0;        ///< peak |K_rel - mean| / mean
  double nonlinearity_sigma_ppm = 0.0;  ///< 1-sigma of the fitted deviation at the peak
  double scale_error_ppm = 0.0;         ///< mean K_rel - 1
  HarmonicFitResult residual_drift;     ///< rad/s of body rate
  double angle_error_max = 0.0;         ///< rad, largest block mean
  double angle_error_rms = 0.0;         ///< rad, rms of the block means
  double angle_error_final = 0.0;       ///< rad, last complete block
  double duration = 0.0;                ///< s
  std::uint64_t samples = 0;
};

class OutputEvaluator {
 public:
  explicit OutputEvaluator(const EvaluationSettings& settings = {});

  /// One output sample and the truth at its stamp.
  void add(Nanoseconds stamp, double theta_mid, double alpha, double table_rate, double inertial_angle,
           double inertial_rate);
  EvaluationResult result() const;

 private:
  EvaluationSettings settings_;
  PlateauDetector detector_;
  RateGroups groups_;
  bool started_ = false;
  Nanoseconds first_stamp_ = 0, last_stamp_ = 0;
  double alpha0_ = 0.0, truth0_ = 0.0;
  double error_max_ = 0.0, error_sq_ = 0.0, error_last_ = 0.0;
  double block_sum_ = 0.0;
  std::uint64_t block_n_ = 0, blocks_ = 0;
  Nanoseconds block_start_ = 0;
  std::uint64_t samples_ = 0;
};

}  // namespace core
}  // namespace hrg_gyro
