// Root-cause diagnosis from the fitted scale-factor harmonics, to first order (docs/math.md,
// 'Pickoff defects to first order'):
//   K(theta) / K0 = 1 - (gc - gs) F cos 2theta - (dc - ds) F sin 2theta - (3 a^2 / 4) cos 4theta
// so the cos 2theta term reads the channel gain mismatch gc - gs, the sin 2theta term the
// misplacement difference dc - ds (rad) and the cos 4theta term the pickoff ratio a = A/d0;
// F = (A^2 + B^2) / (A^2 - B^2) from the wave's quadrature. The defects are read relative to the
// correction matrix P in force during the calibration, so they are what P has left over, and the
// recommended P is the current one plus the change that cancels them:
//   p1 += (gc - gs) / 2, p2 -= (gc - gs) / 2, p3 += (dc - ds) / 2, p4 -= (dc - ds) / 2
// (only the differences show in K; the common parts are an angle offset and a gain, invisible to
// the scale factor). Caveat: the resonator's own anisotropy also makes 2theta terms; the diagnosis
// attributes everything to the pickoffs (the generator-mode P fit separates the two).
//
// Uncertainties combine the fit's standard errors with the first-order truncation (better
// than 1e-3 relative for defects <= 1e-3, 1 % at A/d0 = 0.2), taken as kTruncation of each value.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "hrg_gyro/core/estimation/harmonic_fit.h"
#include "hrg_gyro/core/model/correction_matrix.h"

namespace hrg_gyro {
namespace core {

struct DefectDiagnosis {
  bool valid = false;
  std::string note;            ///< why not valid, or what limits it
  double frequency = 0.0;      ///< Hz of the fit it was read from (NaN: frequency independent)
  double gain_mismatch = 0.0;  ///< gc - gs (relative)
  double gain_mismatch_std = 0.0;
  double misplacement_difference = 0.0;  ///< dc - ds, rad
  double misplacement_difference_std = 0.0;
  double pickoff_ratio_squared = 0.0;  ///< (A/d0)^2; may come out negative within its error
  double pickoff_ratio_squared_std = 0.0;
  double pickoff_ratio = 0.0;      ///< A/d0 = sqrt(max(0, ratio^2))
  double pickoff_ratio_std = 0.0;  ///< from the ratio^2 error (one-sided near 0)
  double quadrature_factor = 1.0;  ///< F used
  CorrectionMatrix current_correction;
  CorrectionMatrix recommended_correction;
  std::array<double, 4> recommended_correction_std{};
};

/// Relative first-order truncation error assumed for each diagnosed value.
constexpr double kDiagnosisTruncation = 0.01;

/// F = (A^2 + B^2) / (A^2 - B^2) from the quadrature ratio B/A (|B/A| < 1).
double quadratureFactor(double quadrature_ratio);

/// Reads the defects from one scale-factor fit (orders must include 2 and 4 for the full
/// diagnosis; what is missing is reported in note and left at 0 with valid = false).
DefectDiagnosis diagnoseDefects(const HarmonicFitResult& scale_factor, double quadrature_ratio,
                                const CorrectionMatrix& current, double frequency = NAN);

/// One line per quantity for logs and the command line, e.g.
/// "gain mismatch gc - gs = 3.51e-04 +- 3.6e-06".
std::string describe(const DefectDiagnosis& diagnosis);

}  // namespace core
}  // namespace hrg_gyro
