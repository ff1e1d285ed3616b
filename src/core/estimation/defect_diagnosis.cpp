#include "hrg_gyro/core/estimation/defect_diagnosis.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace hrg_gyro {
namespace core {
namespace {

// Coefficient and standard error of order k, or false when the fit lacks it.
bool term(const HarmonicFitResult& fit, int k, bool cosine, double* value, double* std) {
  for (std::size_t i = 0; i < fit.orders.size(); ++i) {
    if (fit.orders[i] != k) continue;
    *value = cosine ? fit.cos[i] : fit.sin[i];
    const std::vector<double>& s = cosine ? fit.cos_std : fit.sin_std;
    *std = i < s.size() ? s[i] : 0.0;
    return true;
  }
  return false;
}

double combined(double fit_std, double value) { return std::hypot(fit_std, kDiagnosisTruncation * value); }

}  // namespace

double quadratureFactor(double quadrature_ratio) {
  const double q2 = quadrature_ratio * quadrature_ratio;
  return std::isfinite(q2) && q2 < 1.0 ? (1.0 + q2) / (1.0 - q2) : 1.0;
}

DefectDiagnosis diagnoseDefects(const HarmonicFitResult& k, double quadrature_ratio, const CorrectionMatrix& current,
                                double frequency) {
  DefectDiagnosis d;
  d.frequency = frequency;
  d.current_correction = current;
  d.recommended_correction = current;
  if (!k.ok || !(k.mean < 0.0)) {
    d.note = "no usable scale-factor fit";
    return d;
  }
  const double f = quadratureFactor(std::isfinite(quadrature_ratio) ? quadrature_ratio : 0.0);
  d.quadrature_factor = f;
  const double k0 = k.mean;
  double c2 = 0, c2s = 0, s2 = 0, s2s = 0, c4 = 0, c4s = 0;
  const bool has2 = term(k, 2, true, &c2, &c2s) && term(k, 2, false, &s2, &s2s);
  const bool has4 = term(k, 4, true, &c4, &c4s);
  if (has2) {
    // K cos2 coefficient = -K0 (gc - gs) F; sin2 coefficient = -K0 (dc - ds) F.
    d.gain_mismatch = -c2 / (k0 * f);
    d.gain_mismatch_std = combined(c2s / std::abs(k0 * f), d.gain_mismatch);
    d.misplacement_difference = -s2 / (k0 * f);
    d.misplacement_difference_std = combined(s2s / std::abs(k0 * f), d.misplacement_difference);
    const double half_gain = d.gain_mismatch / 2, half_place = d.misplacement_difference / 2;
    d.recommended_correction.p[0] += half_gain;
    d.recommended_correction.p[1] -= half_gain;
    d.recommended_correction.p[2] += half_place;
    d.recommended_correction.p[3] -= half_place;
    d.recommended_correction_std = {d.gain_mismatch_std / 2, d.gain_mismatch_std / 2, d.misplacement_difference_std / 2,
                                    d.misplacement_difference_std / 2};
  }
  if (has4) {
    // K cos4 coefficient = -K0 (3/4) a^2.
    d.pickoff_ratio_squared = -4.0 * c4 / (3.0 * k0);
    d.pickoff_ratio_squared_std = combined(4.0 * c4s / (3.0 * std::abs(k0)), d.pickoff_ratio_squared);
    d.pickoff_ratio = std::sqrt(std::max(0.0, d.pickoff_ratio_squared));
    // d(a) = d(a^2) / (2a); near a = 0 the error of a is sqrt(error of a^2) (one-sided).
    d.pickoff_ratio_std = d.pickoff_ratio > std::sqrt(d.pickoff_ratio_squared_std)
                              ? d.pickoff_ratio_squared_std / (2.0 * d.pickoff_ratio)
                              : std::sqrt(d.pickoff_ratio_squared_std);
  }
  d.valid = has2 && has4;
  if (!has2)
    d.note = "scale-factor fit without the 2 theta harmonic: gain and misplacement not diagnosed";
  else if (!has4)
    d.note = "scale-factor fit without the 4 theta harmonic: A/d0 not diagnosed";
  else if (d.pickoff_ratio_squared < 0.0)
    d.note = "negative cos 4theta reading: not a capacitive pickoff nonlinearity (A/d0 set to 0)";
  return d;
}

std::string describe(const DefectDiagnosis& d) {
  char buf[512];
  std::string out;
  if (std::isfinite(d.frequency)) {
    std::snprintf(buf, sizeof buf, "at %.3f Hz:\n", d.frequency);
    out += buf;
  }
  if (!d.note.empty()) out += "  note: " + d.note + "\n";
  std::snprintf(buf, sizeof buf,
                "  gain mismatch gc - gs           = %+.3e +- %.1e\n"
                "  misplacement difference dc - ds = %+.3e +- %.1e rad\n"
                "  pickoff ratio A/d0              = %.4f +- %.4f\n"
                "  recommended P = [%+.3e, %+.3e, %+.3e, %+.3e] (now [%+.3e, %+.3e, %+.3e, %+.3e])\n",
                d.gain_mismatch, d.gain_mismatch_std, d.misplacement_difference, d.misplacement_difference_std,
                d.pickoff_ratio, d.pickoff_ratio_std, d.recommended_correction.p[0], d.recommended_correction.p[1],
                d.recommended_correction.p[2], d.recommended_correction.p[3], d.current_correction.p[0],
                d.current_correction.p[1], d.current_correction.p[2], d.current_correction.p[3]);
  return out + buf;
}

}  // namespace core
}  // namespace hrg_gyro
