#include "hrg_gyro/core/estimation/table_clock_offset.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "hrg_gyro/core/model/model_pair_evaluator.h"

namespace hrg_gyro {
namespace core {
namespace {

// The transitions disagree beyond their noise when their reduced chi-square exceeds this (and their
// spread a millisecond): the offset itself moved during the session.
constexpr double kChangedChiSquare = 25.0;
constexpr double kChangedSpread = 1e-3;
// s the changes of rate must span for the offset's drift (the clocks' rate difference) to be fitted.
constexpr double kMinDriftSpan = 60.0;

std::string milliseconds(double s) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g ms", 1e3 * s);
  return buf;
}

struct OffsetRange {
  double lo, hi;  // the smallest and the largest transition offset, s
};

/// offset = a + rate_error (t - mean t) through the transitions' offsets, by least squares where the
/// changes span a minute or more: the offset, the rate error and their standard errors, the spread,
/// whether the offset stepped. Needs at least one transition.
OffsetRange fitOffsets(TableClockOffsetResult* result) {
  TableClockOffsetResult& r = *result;
  const double n = static_cast<double>(r.transitions.size());
  double noise = 0.0, lo = r.transitions.front().offset, hi = lo, mean_t = 0.0, mean_offset = 0.0;
  const Nanoseconds t0 = r.transitions.front().stamp;
  for (const TableClockTransition& t : r.transitions) {
    noise += t.offset_noise * t.offset_noise;
    lo = std::min(lo, t.offset);
    hi = std::max(hi, t.offset);
    mean_t += toSeconds(t.stamp - t0) / n;
    mean_offset += t.offset / n;
  }
  double stt = 0.0, sto = 0.0;
  for (const TableClockTransition& t : r.transitions) {
    const double dt = toSeconds(t.stamp - t0) - mean_t;
    stt += dt * dt;
    sto += dt * (t.offset - mean_offset);
  }
  const double span = toSeconds(r.transitions.back().stamp - t0);
  r.rate_estimated = n >= 3.0 && span >= kMinDriftSpan && stt > 0.0;
  if (r.rate_estimated) r.rate_error = sto / stt;
  double scatter = 0.0, chi = 0.0;
  for (const TableClockTransition& t : r.transitions) {
    const double residual = t.offset - mean_offset - r.rate_error * (toSeconds(t.stamp - t0) - mean_t);
    scatter += residual * residual;
    if (t.offset_noise > 0.0) chi += std::pow(residual / t.offset_noise, 2);
  }
  const double fitted = r.rate_estimated ? 2.0 : 1.0;
  // The noise of the mean (and of the slope), or, where the offsets disagree more than that, their
  // scatter about the line.
  const double residual_variance = n > fitted ? scatter / (n - fitted) : 0.0;
  const double noise_variance = noise / n;
  r.offset = mean_offset;
  r.offset_std = std::sqrt(std::max(noise_variance, n >= 3.0 ? residual_variance : 0.0) / n);
  if (r.rate_estimated) {
    r.rate_error_std = std::sqrt(std::max(noise_variance, residual_variance) / stt);
  }
  r.spread = hi - lo;
  r.changed =
      n > fitted + 1.0 && chi / (n - fitted) > kChangedChiSquare && std::sqrt(residual_variance) > kChangedSpread / 3;
  r.estimated = true;
  return {lo, hi};
}

/// The note of an estimated offset: how many changes, their range, the clock's drift, a step.
void describe(const OffsetRange& range, std::size_t broken, TableClockOffsetResult* result) {
  TableClockOffsetResult& r = *result;
  r.note = std::to_string(r.transitions.size()) + " changes of rate, offsets " + milliseconds(range.lo) + " to " +
           milliseconds(range.hi);
  if (broken > 0) r.note += " (" + std::to_string(broken) + " more left out: a gap in the samples)";
  if (r.rate_estimated && std::abs(r.rate_error) > 3.0 * r.rate_error_std) {
    char drift[96];
    std::snprintf(drift, sizeof drift, "%.3g +- %.2g", 1e6 * r.rate_error, 1e6 * r.rate_error_std);
    r.note += std::string("; the table's clock runs ") + drift + " ppm " + (r.rate_error > 0.0 ? "fast" : "slow") +
              " against the gyro's";
  }
  if (r.changed) {
    r.note +=
        ": they disagree far beyond their noise and a steady drift, so the offset stepped during the session: from " +
        milliseconds(r.transitions.front().offset) + " at the first change to " +
        milliseconds(r.transitions.back().offset) + " at the last";
  }
}

}  // namespace

TableClockOffsetEstimator::TableClockOffsetEstimator(const TableClockOffsetSettings& settings) : settings_(settings) {
  if (!(settings_.window > 0.0) || !(settings_.max_rate > 0.0) || !(settings_.max_transition > 0.0) ||
      !(settings_.min_rate_change > 0.0) || !(settings_.guard >= 0.0)) {
    throw std::invalid_argument("table clock offset: window, max_rate, max_transition and min_rate_change must be > 0");
  }
}

void TableClockOffsetEstimator::keep(std::deque<Sample>* into, Nanoseconds origin, Nanoseconds stamp, double theta,
                                     double phi, int side) {
  // Thinned: the window means need no more, and memory stays a few MB for 64 transitions at 10 kHz.
  if (last_kept_ != 0 && toSeconds(stamp - last_kept_) < 1.0 / settings_.max_rate) return;
  last_kept_ = stamp;
  into->push_back({toSeconds(stamp - origin), theta, phi, side});
}

void TableClockOffsetEstimator::add(Nanoseconds stamp, double theta, double table_angle, double table_rate,
                                    std::uint64_t plateau, double plateau_rate, bool settled) {
  (void)table_rate;
  if (!std::isfinite(theta) || !std::isfinite(table_angle)) return;
  // A gap in the samples (lost samples, a table outage) breaks the path the model is integrated
  // along: a change of rate with one in it is not measured, and a plateau's tail starts anew.
  const bool gap = last_added_ != 0 && toSeconds(stamp - last_added_) > settings_.max_sample_gap;
  last_added_ = stamp;
  if (gap) {
    if (in_transition_) {
      in_transition_ = false;
      open_samples_.clear();
      ++broken_;
    }
    on_plateau_ = false;
    tail_.clear();
  }
  if (in_transition_) {
    addInTransition(stamp, theta, table_angle, plateau, plateau_rate, settled);
  } else if (settled) {
    addOnPlateau(stamp, theta, table_angle, plateau, plateau_rate);
  } else if (on_plateau_ && !tail_.empty()) {
    beginTransition(stamp, theta, table_angle);
  }
}

void TableClockOffsetEstimator::addInTransition(Nanoseconds stamp, double theta, double table_angle,
                                                std::uint64_t plateau, double plateau_rate, bool settled) {
  const double t = toSeconds(stamp - open_origin_);
  int side = 0;
  if (settled && plateau != before_plateau_) {
    if (!has_after_ || plateau != after_plateau_) {
      has_after_ = true;
      after_plateau_ = plateau;
      after_start_ = t;
    }
    side = 1;
  }
  keep(&open_samples_, open_origin_, stamp, theta, table_angle, side);
  if (side == 1 && t - after_start_ >= settings_.window) {
    completeTransition(stamp, t, plateau, plateau_rate);
  } else if (t > settings_.max_transition) {
    in_transition_ = false;  // no settled plateau after it in time: nothing to measure
    open_samples_.clear();
    on_plateau_ = false;
  }
}

void TableClockOffsetEstimator::completeTransition(Nanoseconds stamp, double t, std::uint64_t plateau,
                                                   double plateau_rate) {
  // Settled long enough on the new plateau: the change is complete.
  if (std::abs(plateau_rate - before_rate_) >= settings_.min_rate_change && done_.size() < settings_.max_transitions) {
    Transition done;
    done.origin = open_origin_;
    done.left = left_;
    done.rate_before = before_rate_;
    done.rate_after = plateau_rate;
    done.samples.assign(open_samples_.begin(), open_samples_.end());
    done_.push_back(std::move(done));
  }
  in_transition_ = false;
  // The new plateau's first window is where the next change will be measured from, if it is that short.
  on_plateau_ = true;
  plateau_ = plateau;
  plateau_rate_ = plateau_rate;
  tail_.clear();
  tail_origin_ = stamp;
  for (const Sample& s : open_samples_) {
    if (s.side == 1) tail_.push_back({s.t - t, s.theta, s.phi, -1});
  }
  open_samples_.clear();
}

void TableClockOffsetEstimator::addOnPlateau(Nanoseconds stamp, double theta, double table_angle, std::uint64_t plateau,
                                             double plateau_rate) {
  if (!on_plateau_ || plateau != plateau_) {
    on_plateau_ = true;
    plateau_ = plateau;
    tail_.clear();
    tail_origin_ = stamp;
  }
  plateau_rate_ = plateau_rate;
  keep(&tail_, tail_origin_, stamp, theta, table_angle, -1);
  const double t = toSeconds(stamp - tail_origin_);
  while (!tail_.empty() && t - tail_.front().t > settings_.window + settings_.guard) tail_.pop_front();
}

void TableClockOffsetEstimator::beginTransition(Nanoseconds stamp, double theta, double table_angle) {
  // The table left its settled plateau: a change of rate begins. Times from the tail's first sample.
  in_transition_ = true;
  has_after_ = false;
  before_plateau_ = plateau_;
  before_rate_ = plateau_rate_;
  left_ = stamp;
  const double shift = tail_.front().t;
  open_origin_ = tail_origin_ + toNanoseconds(shift);
  open_samples_.clear();
  // The guard before the departure counts as part of the change (the table may have been moving).
  const double guard_from = toSeconds(stamp - tail_origin_) - settings_.guard;
  for (const Sample& s : tail_) open_samples_.push_back({s.t - shift, s.theta, s.phi, s.t < guard_from ? -1 : 0});
  keep(&open_samples_, open_origin_, stamp, theta, table_angle, 0);
  on_plateau_ = false;
  tail_.clear();
}

bool TableClockOffsetEstimator::measure(const Transition& tr, ModelPairEvaluator* models, double earth_rate,
                                        double frequency, double k0, TableClockTransition* out) {
  // theta - I along the path: constant where the logged table angle is the true one shifted by a
  // constant, so its means on the two sides differ by K0 offset (W_b - W_a).
  double integral = 0.0, k_previous = 0.0, d_previous = 0.0;
  double sum[2] = {0.0, 0.0}, squares[2] = {0.0, 0.0};
  double count[2] = {0.0, 0.0};
  double k_change = 0.0, k_count = 0.0;  // K over the change: its harmonics are not K0's
  for (std::size_t i = 0; i < tr.samples.size(); ++i) {
    const Sample& s = tr.samples[i];
    double kk, dd;
    models->evaluate(s.theta, frequency, &kk, &dd);
    if (i > 0) {
      const Sample& p = tr.samples[i - 1];
      const double dt = s.t - p.t;
      integral += 0.5 * (kk + k_previous) * (s.phi - p.phi + earth_rate * dt) + 0.5 * (dd + d_previous) * dt;
    }
    k_previous = kk;
    d_previous = dd;
    if (s.side == 0) {
      k_change += kk;
      k_count += 1.0;
      continue;
    }
    const int side = s.side > 0 ? 1 : 0;
    const double y = s.theta - integral;
    sum[side] += y;
    squares[side] += y * y;
    count[side] += 1.0;
  }
  if (count[0] < 3.0 || count[1] < 3.0) return false;
  const double change = (k_count > 0.0 ? k_change / k_count : k0) * (tr.rate_after - tr.rate_before);
  TableClockTransition& t = *out;
  t.stamp = tr.left;
  t.rate_before = tr.rate_before;
  t.rate_after = tr.rate_after;
  const double mean0 = sum[0] / count[0], mean1 = sum[1] / count[1];
  t.offset = (mean1 - mean0) / change;
  const double var0 = std::max(0.0, squares[0] / count[0] - mean0 * mean0) / (count[0] - 1.0);
  const double var1 = std::max(0.0, squares[1] / count[1] - mean1 * mean1) / (count[1] - 1.0);
  t.offset_noise = std::sqrt(var0 + var1) / std::abs(change);
  return true;
}

TableClockOffsetResult TableClockOffsetEstimator::estimate(const HarmonicModel& k, const HarmonicModel& d,
                                                           double earth_rate, double frequency) const {
  TableClockOffsetResult r;
  ModelPairEvaluator models(k, d);
  const double k0 = k.meanAt(frequency);
  for (const Transition& tr : done_) {
    TableClockTransition t;
    if (measure(tr, &models, earth_rate, frequency, k0, &t)) r.transitions.push_back(t);
  }
  if (r.transitions.empty()) {
    r.note = done_.empty() ? "no change of the table's rate was seen settled on both sides by both streams"
                           : "the changes of rate seen had too few samples on their plateaus";
    if (broken_ > 0) r.note += " (" + std::to_string(broken_) + " left out: a gap in the samples)";
    return r;
  }
  const OffsetRange range = fitOffsets(&r);
  describe(range, broken_, &r);
  return r;
}

}  // namespace core
}  // namespace hrg_gyro
