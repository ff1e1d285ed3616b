#include "hrg_gyro/core/calibration/thermal_method.h"

#include <algorithm>
#include <cmath>
#include <ctime>
#include <sstream>

#include "hrg_gyro/core/calibration/outcome_from_fits.h"
#include "hrg_gyro/core/common/number_format.h"
#include "hrg_gyro/core/common/units.h"
#include "hrg_gyro/core/estimation/thermal_estimator.h"

namespace hrg_gyro {
namespace core {
namespace {

/// Fraction of bins with at least min_time s of swept data in the per-bin sums.
double coverageOf(const std::vector<double>& swept, double min_time) {
  if (swept.empty()) return 0.0;
  const auto covered = std::count_if(swept.begin(), swept.end(), [&](double t) { return t >= min_time && t > 0.0; });
  return static_cast<double>(covered) / static_cast<double>(swept.size());
}

}  // namespace

ThermalMethod::ThermalMethod(const CalibrationSettings& s, double k0)
    : settings_(s),
      rates_(s.bins, s.window, s.window_span, k0, maxFittedOrder(s.scale_factor_orders, s.drift_orders),
             s.group_tolerance, s.plateau.max_gap, s.thermal.slice_width, s.thermal.max_slices) {}

void ThermalMethod::addSample(const PlateauSample& s) {
  if (s.plateau.is_static) return;
  if (!std::isfinite(s.frequency)) {
    ++no_frequency_;
    return;
  }
  const std::vector<double>& fixed = settings_.thermal.frequency_nodes;
  if (!fixed.empty() && (s.frequency < fixed.front() || s.frequency > fixed.back())) {
    ++out_of_range_;
    return;
  }
  if (!rates_.add(s.stamp, s.theta, s.theta, s.plateau.id, s.plateau.rate, s.rotation_rate, s.frequency)) {
    ++slice_limit_;
    return;
  }
  ++samples_;
  f_min_ = std::min(f_min_, s.frequency);
  f_max_ = std::max(f_max_, s.frequency);
}

std::vector<double> ThermalMethod::nodes() const {
  const ThermalSettings& t = settings_.thermal;
  if (!t.frequency_nodes.empty()) return t.frequency_nodes;
  if (!(f_max_ > f_min_)) return {};
  std::vector<double> n(t.node_count);
  for (int j = 0; j < t.node_count; ++j) n[j] = f_min_ + (f_max_ - f_min_) * j / (t.node_count - 1);
  n.back() = f_max_;
  return n;
}

std::vector<double> ThermalMethod::intervalCoverage(const RateGroup& group, const std::vector<double>& nodes) const {
  const std::size_t intervals = nodes.size() - 1;
  std::vector<std::vector<double>> swept(intervals, std::vector<double>(rates_.binCount(), 0.0));
  for (const auto& kv : group.slices) {
    // A slice counts for the interval its centre (held inside the node range) falls in.
    const double f = std::clamp(rates_.sliceCenter(kv.first), nodes.front(), nodes.back());
    std::size_t i = static_cast<std::size_t>(std::upper_bound(nodes.begin(), nodes.end(), f) - nodes.begin());
    i = std::min(intervals, std::max<std::size_t>(i, 1)) - 1;
    for (int b = 0; b < rates_.binCount(); ++b) swept[i][b] += kv.second.binSwept(b);
  }
  std::vector<double> out(intervals);
  for (std::size_t i = 0; i < intervals; ++i) out[i] = coverageOf(swept[i], minBinTime());
  return out;
}

double ThermalMethod::worstCoverage(const std::vector<double>& nodes, std::size_t* worst) const {
  const auto order = rates_.byDuration();
  if (order.size() < 2 || nodes.size() < 2) return 0.0;
  double w = 1.0;
  for (std::size_t g = 0; g < 2; ++g) {
    const std::vector<double> c = intervalCoverage(rates_.groups()[order[g]], nodes);
    for (std::size_t i = 0; i < c.size(); ++i) {
      if (c[i] < w) {
        w = c[i];
        if (worst) *worst = i;
      }
    }
  }
  return w;
}

bool ThermalMethod::complete() const { return progress().fraction >= 1.0; }

CalibrationProgress ThermalMethod::progress() const {
  CalibrationProgress p;
  const std::vector<double> n = nodes();
  const auto order = rates_.byDuration();
  std::ostringstream s;
  s << "thermal: " << order.size() << " rate group(s), " << rates_.sliceCount() << " frequency slice(s)";
  if (samples_ > 0) s << ", " << formatShort(f_min_, 8) << ".." << formatShort(f_max_, 8) << " Hz";
  const double cov = worstCoverage(n, nullptr);
  if (order.size() >= 2 && n.size() >= 2) s << ", worst node-interval coverage " << formatShort(100 * cov) << " %";
  p.fraction = std::min(1.0, cov / settings_.gates.min_coverage);
  p.summary = s.str();
  return p;
}

void ThermalMethod::summarizeGroups(CalibrationOutcome* o) const {
  for (std::size_t i : rates_.byDuration()) {
    const RateGroup& g = rates_.groups()[i];
    GroupSummary sum;
    sum.rate = g.meanRate();
    sum.rate_std = g.rateStd();
    sum.duration = g.totalTime();
    sum.samples = g.samples();
    std::vector<double> swept(rates_.binCount(), 0.0);
    for (const auto& kv : g.slices) {
      for (int b = 0; b < rates_.binCount(); ++b) swept[b] += kv.second.binSwept(b);
    }
    sum.coverage = coverageOf(swept, minBinTime());
    sum.turns = g.thetaSwept() / kPi;
    o->plateaus.push_back(sum);
  }
}

void ThermalMethod::noteDroppedSamples(CalibrationOutcome* o) const {
  const ThermalSettings& ts = settings_.thermal;
  if (no_frequency_ > 0) {
    o->notes.push_back(std::to_string(no_frequency_) + " moving-plateau samples carried no resonator frequency");
  }
  if (out_of_range_ > 0) {
    o->notes.push_back(std::to_string(out_of_range_) + " samples lay outside the frequency nodes [" +
                       formatShort(ts.frequency_nodes.front(), 8) + ", " + formatShort(ts.frequency_nodes.back(), 8) +
                       "] Hz");
  }
  if (slice_limit_ > 0) {
    o->notes.push_back(std::to_string(slice_limit_) + " samples fell beyond thermal/max_slices (" +
                       std::to_string(ts.max_slices) + ") and were dropped");
  }
}

void ThermalMethod::gateData(const std::vector<double>& n, const RateGroup& g1, const RateGroup& g2,
                             CalibrationOutcome* o) const {
  const QualityLimits& q = settings_.gates;
  const ThermalSettings& ts = settings_.thermal;
  double narrowest = INFINITY;
  for (std::size_t j = 1; j < n.size(); ++j) narrowest = std::min(narrowest, n[j] - n[j - 1]);
  o->frequency_nodes = n;
  o->gate("node_spacing", narrowest >= ts.slice_width, narrowest, ts.slice_width,
          "narrowest node interval " + formatShort(narrowest) + " Hz against frequency slices of " +
              formatShort(ts.slice_width) +
              " Hz (use fewer nodes, a finer thermal/slice_width, or the dual_rate method)");
  const double w1 = g1.meanRate(), w2 = g2.meanRate();
  o->duration = g1.totalTime() + g2.totalTime();
  std::size_t worst = 0;
  o->coverage = worstCoverage(n, &worst);
  o->gate("coverage", o->coverage >= q.min_coverage, o->coverage, q.min_coverage,
          "theta bins covered at both rates in every node interval: worst " + formatShort(100 * o->coverage) +
              " % in [" + formatShort(n[worst], 8) + ", " + formatShort(n[worst + 1], 8) + "] Hz");
  o->gate("rate_separation", std::abs(w1 - w2) >= q.min_rate_separation, std::abs(w1 - w2), q.min_rate_separation,
          "plateau rates " + formatShort(w1) + " and " + formatShort(w2) + " rad/s");
  const double noise = std::max(g1.rateStd() / std::abs(w1), g2.rateStd() / std::abs(w2));
  o->gate("rate_noise", noise <= q.max_rate_noise, noise, q.max_rate_noise,
          "reported table rate scatters by " + formatShort(100 * noise) + " % within a plateau");
}

double ThermalMethod::gateNodes(const std::vector<double>& n, const ThermalEstimate& e, const GyroParameters& prior,
                                CalibrationOutcome* o) const {
  const QualityLimits& q = settings_.gates;
  double k0_max = -INFINITY, change = 0.0, hstd = 0.0, k0_abs_mean = 0.0, slope = 0.0;
  for (std::size_t j = 0; j < n.size(); ++j) {
    const HarmonicFitResult& k = e.k[j];
    k0_max = std::max(k0_max, k.mean);
    const double k0_prior = prior.scale_factor.meanAt(n[j]);
    change = std::max(change, std::abs(k.mean - k0_prior) / std::abs(k0_prior));
    if (!k.orders.empty()) hstd = std::max(hstd, largestHarmonicStd(k) / std::abs(k.mean));
    slope = std::max(slope, slopeBound(k) * std::abs(k.mean));
    k0_abs_mean += std::abs(k.mean) / static_cast<double>(n.size());
    o->nonlinearity_ppm = std::max(o->nonlinearity_ppm, 1e6 * e.k_model.peakDeviation(n[j]) / std::abs(k.mean));
  }
  o->gate("k0_sign", k0_max < 0.0, k0_max, 0.0,
          "largest K0 over the nodes = " + formatShort(k0_max) + " must be negative");
  o->gate("k0_change", change <= q.max_k0_change, change, q.max_k0_change,
          "K0 moved by up to " + formatShort(100 * change) + " % from the prior");
  const double residual = e.k_residual_rms / k0_abs_mean;
  o->gate("residual", residual <= q.max_relative_residual, residual, q.max_relative_residual,
          "rms of the binned K (moved to the middle frequency) about the fit is " + formatShort(residual) + " of |K0|");
  o->gate("harmonic_std", hstd <= q.max_harmonic_std, hstd, q.max_harmonic_std,
          "largest K harmonic standard error at any node is " + formatShort(hstd * 1e6) + " ppm of |K0|");
  return slope;
}

double ThermalMethod::errorBound(double slope, const RateGroup& g1, const RateGroup& g2) const {
  const double w1 = g1.meanRate(), w2 = g2.meanRate();
  double sigma = 0.0;
  for (const RateGroup* g : {&g1, &g2}) {
    double noise_time = 0.0, time = 0.0;
    for (const auto& kv : g->slices) {
      noise_time += kv.second.windowNoise() * kv.second.totalTime();
      time += kv.second.totalTime();
    }
    if (time > 0.0) sigma = std::max(sigma, noise_time / time);
  }
  const double tau = std::max(g1.window, g2.window);
  return slope * std::max(std::abs(w1), std::abs(w2)) * tau + 2.0 * std::sqrt(2.0) * sigma / (std::abs(w1 - w2) * tau);
}

CalibrationOutcome ThermalMethod::finish(const GyroParameters& prior) const {
  CalibrationOutcome o;
  o.method = kind();
  const QualityLimits& q = settings_.gates;
  const ThermalSettings& ts = settings_.thermal;
  const auto order = rates_.byDuration();
  summarizeGroups(&o);
  o.samples = samples_;
  noteDroppedSamples(&o);
  o.gate("samples", samples_ >= q.min_samples, static_cast<double>(samples_), static_cast<double>(q.min_samples),
         std::to_string(samples_) + " wave samples with a frequency on moving plateaus");
  if (order.size() < 2) {
    o.gate("plateau_groups", false, static_cast<double>(order.size()), 2.0,
           "need plateaus at two distinct table rates, found " + std::to_string(order.size()));
    o.decide();
    return o;
  }
  const std::vector<double> n = nodes();
  if (n.size() < 2) {
    o.gate("frequency_nodes", false, 0.0, static_cast<double>(ts.nodeCount()),
           "the data span no frequency range (" +
               (samples_ ? formatShort(f_min_, 8) + " Hz only" : std::string("none")) +
               "): a frequency-dependent model cannot be fitted; use dual_rate");
    o.decide();
    return o;
  }
  const RateGroup& g1 = rates_.groups()[order[0]];
  const RateGroup& g2 = rates_.groups()[order[1]];
  gateData(n, g1, g2, &o);

  const double earth = prior.earth_rate.verticalRate();
  const FrequencyInterpolator interpolator(n, ts.interpolation);
  const ThermalEstimate e =
      estimateThermal(g1, g1.meanRate() + earth, g2, g2.meanRate() + earth, interpolator, rates_.binCount(),
                      settings_.scale_factor_orders, settings_.drift_orders, minBinTime(), INFINITY);
  if (!e.ok) {
    o.gate("fit", false, 0.0, 0.0, e.reason);
    o.decide();
    return o;
  }
  o.scale_factor = e.k;
  o.drift = e.d;
  o.binned = e.binned;
  o.smoothing_factor = e.smoothing_factor;
  o.gate("fit_condition", e.condition_number <= q.max_condition, e.condition_number, q.max_condition,
         "frequency-dependent fit condition number " + formatShort(e.condition_number));
  // Per node: K0 sign and change from the prior, largest K-harmonic standard error, peak
  // nonlinearity; the paper-style error bound with the steepest node's model.
  const double slope = gateNodes(n, e, prior, &o);
  o.error_bound = errorBound(slope, g1, g2);
  o.parameters = prior;
  o.parameters.scale_factor = e.k_model;
  o.parameters.drift = e.d_model;
  o.parameters.calibration.method = ParameterOrigin::calibratedBy(o.method);
  o.parameters.calibration.time = utcNow();
  o.notes.push_back("K and D are splines (" + std::string(toString(ts.interpolation)) + ") over " +
                    std::to_string(n.size()) + " frequency nodes " + formatShort(n.front(), 8) + ".." +
                    formatShort(n.back(), 8) +
                    " Hz; outside them the processor holds the end values and flags the samples");
  o.decide();
  return o;
}

}  // namespace core
}  // namespace hrg_gyro
