#include "hrg_gyro/core/evaluation/session_summary.h"

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

namespace hrg_gyro {
namespace core {
namespace {

std::string line(const char* fmt, double a, double b, double c, double d) {
  char buf[256];
  std::snprintf(buf, sizeof buf, fmt, a, b, c, d);
  return buf;
}

void printModel(std::ostream& out, const char* title, const char* unit, double scale, const HarmonicFitResult& inj,
                const HarmonicFitResult& est) {
  out << title << " (" << unit << ")\n";
  out << "  term        injected      estimated    std error   (est-inj)/std\n";
  auto row = [&](const std::string& name, double i, double e, double s) {
    const double z = s > 0 ? (e - i) / s : 0.0;
    out << "  " << name << std::string(10 - std::min<std::size_t>(10, name.size()), ' ')
        << line("%13.6e  %13.6e  %10.2e  %+8.2f\n", i * scale, e * scale, s * scale, z);
  };
  row("mean", inj.mean, est.mean, est.mean_std);
  for (std::size_t j = 0; j < est.orders.size(); ++j) {
    const int k = est.orders[j];
    double ic = 0.0, is = 0.0;
    for (std::size_t m = 0; m < inj.orders.size(); ++m) {
      if (inj.orders[m] == k) {
        ic = inj.cos[m];
        is = inj.sin[m];
      }
    }
    row("cos " + std::to_string(k) + "th", ic, est.cos[j], est.cos_std[j]);
    row("sin " + std::to_string(k) + "th", is, est.sin[j], est.sin_std[j]);
  }
}

}  // namespace

void printSessionSummary(std::ostream& out, const SessionSummary& s) {
  const CalibrationOutcome& c = s.calibration;
  out << "\n=== hrg_gyro session summary ===\n";
  out << "calibration: method " << (s.has_calibration ? nameOf(c.method) : ParameterOrigin::none().name()) << ", "
      << (c.accepted ? "ACCEPTED" : "REFUSED");
  if (!c.accepted) out << " (" << c.reason << ")";
  out << line(", %.0f s of data, coverage %.1f %%, smoothing factor %.6f (corrected)\n", c.duration, 100 * c.coverage,
              c.smoothing_factor, 0.0);
  for (const GroupSummary& g : c.plateaus) {
    out << line("  plateau %+.5f rad/s: %.1f s, %.2f half-turns of theta, coverage %.1f %%\n", g.rate, g.duration,
                g.turns, 100 * g.coverage);
  }
  if (!c.scale_factor.empty()) {
    printModel(out, "K(theta), scale factor", "dimensionless", 1.0, s.injected.scale_factor, c.scale_factor[0]);
    printModel(out, "D(theta), drift", "rad/s", 1.0, s.injected.drift, c.drift[0]);
  }
  out << line("injected peak nonlinearity of K (exact, all orders): %.1f ppm; fitted model: %.1f ppm\n",
              s.injected.nonlinearity_ppm, c.nonlinearity_ppm, 0, 0);
  if (!c.scale_factor.empty()) {
    // The calibration's own error, noise free: estimated minus exact injected model.
    const HarmonicFitResult& e = c.scale_factor[0];
    const HarmonicFitResult& i = s.injected.scale_factor;
    std::vector<double> dc(e.orders.size()), ds(e.orders.size());
    for (std::size_t j = 0; j < e.orders.size(); ++j) {
      dc[j] = e.cos[j] - (j < i.cos.size() ? i.cos[j] : 0.0);
      ds[j] = e.sin[j] - (j < i.sin.size() ? i.sin[j] : 0.0);
    }
    const double err = HarmonicModel(e.orders, 0.0, dc, ds).peakDeviation() / std::abs(i.mean);
    out << line("model error against the injected model (exact, no verification noise): peak %.3f ppm\n", 1e6 * err, 0,
                0, 0);
  }
  out << "verification (processor output against ground truth, dual-rate on the output):\n";
  out << "                           before (uncalibrated)   after (calibrated)\n";
  auto both = [&](const char* name, double b, double a, const char* unit) {
    char buf[256];
    std::snprintf(buf, sizeof buf, "  %-24s %14.3f %20.3f   %s\n", name, b, a, unit);
    out << buf;
  };
  both("peak nonlinearity", s.before.nonlinearity_ppm, s.after.nonlinearity_ppm, "ppm");
  both("  (1-sigma of the peak)", s.before.nonlinearity_sigma_ppm, s.after.nonlinearity_sigma_ppm, "ppm");
  both("scale-factor error", s.before.scale_error_ppm, s.after.scale_error_ppm, "ppm");
  both("angle error max (1 s means)", s.before.angle_error_max * 1e6, s.after.angle_error_max * 1e6, "urad");
  both("angle error rms (1 s means)", s.before.angle_error_rms * 1e6, s.after.angle_error_rms * 1e6, "urad");
  both("angle error at end", s.before.angle_error_final * 1e6, s.after.angle_error_final * 1e6, "urad");
  out << line("  over %.1f s of verification profile, %.0f samples\n", s.after.duration,
              static_cast<double>(s.after.samples), 0, 0);
  for (const std::string& w : s.warnings) out << "WARNING: " << w << "\n";
  if (!s.before.ok) out << "WARNING: before: " << s.before.reason << "\n";
  if (!s.after.ok) out << "WARNING: after: " << s.after.reason << "\n";
  out << line("nonlinearity_ppm before=%.3f after=%.3f\n", s.before.nonlinearity_ppm, s.after.nonlinearity_ppm, 0, 0);
  out.flush();
}

}  // namespace core
}  // namespace hrg_gyro
