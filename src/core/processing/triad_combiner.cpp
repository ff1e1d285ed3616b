#include "hrg_gyro/core/processing/triad_combiner.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "hrg_gyro/core/common/yaml_field.h"
#include "hrg_gyro/core/processing/gyro_processor.h"

namespace hrg_gyro {
namespace core {
namespace {

// A quarter period: far from both a jittered stamp of the same instant and the next sample.
constexpr double kAutoToleranceFraction = 0.25;
// Variances beyond this are not a gyro's (and would overflow M diag M^T): the last sane one stands.
constexpr double kLargestRateVariance = 1e12;
constexpr std::uint8_t kAllAxes = 0x7;

/// a - b, saturated instead of overflowing (stamps are not checked: any int64 may come in).
Nanoseconds difference(Nanoseconds a, Nanoseconds b) {
  Nanoseconds d;
  if (__builtin_sub_overflow(a, b, &d)) {
    return a > b ? std::numeric_limits<Nanoseconds>::max() : std::numeric_limits<Nanoseconds>::min();
  }
  return d;
}

/// Seconds as whole nanoseconds, saturated (a tolerance or wait of any size).
Nanoseconds saturatedNanoseconds(double seconds) {
  const double ns = seconds * 1e9;
  if (!(ns < 9.0e18)) return std::numeric_limits<Nanoseconds>::max();
  return ns <= 0.0 ? 0 : static_cast<Nanoseconds>(ns);
}

void checkFinite(const TriadParameters& triad) {
  if (!triad.axis_to_body.allFinite() || !triad.bias.allFinite()) {
    throw std::invalid_argument("triad combiner: axis_to_body and bias must be finite");
  }
}

}  // namespace

void TriadCombinerSettings::validate() const {
  if (!(stamp_tolerance >= 0.0) || !std::isfinite(stamp_tolerance)) {
    throw ConfigError("stamp_tolerance", "must be >= 0 s (0: a quarter of the sample period)");
  }
  if (!(max_wait > 0.0) || !std::isfinite(max_wait)) throw ConfigError("max_wait", "must be positive (s)");
  if (max_pending < 1) throw ConfigError("max_pending", "must be at least 1 (samples per axis)");
  if (!(initial_rate_variance > 0.0) || !(initial_rate_variance <= kLargestRateVariance)) {
    throw ConfigError("initial_angular_velocity_variance", "must be positive ((rad/s)^2)");
  }
}

TriadCombiner::TriadCombiner(const TriadCombinerSettings& settings, std::shared_ptr<const TriadParameters> triad)
    : settings_(settings),
      queues_{{RingBuffer<Held>(settings.max_pending), RingBuffer<Held>(settings.max_pending),
               RingBuffer<Held>(settings.max_pending)}} {
  try {
    settings_.validate();
  } catch (const ConfigError& e) {
    throw std::invalid_argument(std::string("triad combiner: ") + e.what());
  }
  max_wait_ns_ = saturatedNanoseconds(settings_.max_wait);
  variance_.fill(settings_.initial_rate_variance);
  setParameters(std::move(triad));
}

void TriadCombiner::setParameters(std::shared_ptr<const TriadParameters> triad) {
  if (!triad) throw std::invalid_argument("triad combiner: no triad parameters");
  checkFinite(*triad);
  triad_ = std::move(triad);
  m_ = triad_->axis_to_body;
  bias_ = triad_->bias;
}

void TriadCombiner::add(std::size_t axis, const AxisOutput& in, std::vector<TriadBodySample>* completed) {
  if (axis >= 3) throw std::out_of_range("triad combiner: axis index must be 0, 1 or 2");
  TriadAxisCounters& c = counters_.axes[axis];
  ++c.received;
  if (!(in.dt > 0.0) || !std::isfinite(in.dt) || !std::isfinite(in.dalpha)) {
    ++c.invalid;  // left out: the stamp is then missing on this axis, a gap
    return;
  }
  if (seen_[axis]) {
    if (in.stamp == last_stamp_[axis]) {
      ++c.duplicate;
      return;
    }
    if (in.stamp < last_stamp_[axis]) {
      ++epoch_[axis];
      ++c.epochs;
    }
  }
  seen_[axis] = true;
  last_stamp_[axis] = in.stamp;
  if (in.flags != 0) ++c.flagged;
  RingBuffer<Held>& queue = queues_[axis];
  // A full queue: the oldest stamps held have waited long enough.
  while (queue.size() >= settings_.max_pending) resolve(true, completed);
  queue.push_back(Held{in.stamp, epoch_[axis], in.dt, in.dalpha, in.rate_variance, in.flags});
  resolve(false, completed);
}

void TriadCombiner::flush(std::vector<TriadBodySample>* completed) {
  while (!queues_[0].empty() || !queues_[1].empty() || !queues_[2].empty()) resolve(true, completed);
}

std::size_t TriadCombiner::earliestHead() const {
  std::size_t best = 3;
  for (std::size_t a = 0; a < 3; ++a) {
    if (queues_[a].empty()) continue;
    if (best == 3) {
      best = a;
      continue;
    }
    const Held& h = queues_[a].front();
    const Held& b = queues_[best].front();
    if (h.epoch < b.epoch || (h.epoch == b.epoch && h.stamp < b.stamp)) best = a;
  }
  return best;
}

bool TriadCombiner::waitedOut(const Held& head) const {
  for (std::size_t a = 0; a < 3; ++a) {
    if (queues_[a].size() >= settings_.max_pending) return true;
    if (seen_[a] && epoch_[a] == head.epoch && difference(last_stamp_[a], head.stamp) > max_wait_ns_) return true;
  }
  return false;
}

void TriadCombiner::resolve(bool force, std::vector<TriadBodySample>* completed) {
  for (;;) {
    std::uint8_t nonempty = 0;
    for (std::size_t a = 0; a < 3; ++a) nonempty |= queues_[a].empty() ? 0 : (1u << a);
    if (nonempty == 0) return;
    const Held& first = queues_[earliestHead()].front();
    const bool awaited = nonempty != kAllAxes;  // an axis may still deliver this stamp
    if (awaited && !force && !waitedOut(first)) return;
    // The axes whose head is the earliest stamp (within the tolerance, in its epoch).
    double smallest_dt = INFINITY;
    for (std::size_t a = 0; a < 3; ++a) {
      if (nonempty & (1u << a)) smallest_dt = std::min(smallest_dt, queues_[a].front().dt);
    }
    const Nanoseconds tolerance = saturatedNanoseconds(
        settings_.stamp_tolerance > 0.0 ? settings_.stamp_tolerance : kAutoToleranceFraction * smallest_dt);
    std::uint8_t present = 0;
    for (std::size_t a = 0; a < 3; ++a) {
      if (!(nonempty & (1u << a))) continue;
      const Held& h = queues_[a].front();
      if (h.epoch == first.epoch && difference(h.stamp, first.stamp) <= tolerance) present |= 1u << a;
    }
    if (awaited) ++counters_.timeouts;
    emit(present, completed);
    if (force) return;  // one stamp at a time: the caller decides how far to go
  }
}

void TriadCombiner::emit(std::uint8_t present, std::vector<TriadBodySample>* completed) {
  std::array<const Held*, 3> heads{{nullptr, nullptr, nullptr}};
  for (std::size_t a = 0; a < 3; ++a) {
    if (!(present & (1u << a))) continue;
    heads[a] = &queues_[a].front();
    const double v = heads[a]->variance;
    if (v > 0.0 && v <= kLargestRateVariance) variance_[a] = v;
  }
  completed->emplace_back();
  TriadBodySample& out = completed->back();
  combine(heads, &out);
  out.missing_axes = static_cast<std::uint8_t>(kAllAxes & ~present);
  for (std::size_t a = 0; a < 3; ++a) {
    if (present & (1u << a)) {
      queues_[a].pop_front();
    } else {
      ++counters_.axes[a].missing;
    }
  }
  ++counters_.samples;
  if (out.integrated()) ++counters_.integrated;
  if (out.flags & kTriadFlagGap) ++counters_.gaps;
  if (out.flags & kTriadFlagReset) ++counters_.resets;
  if (out.flags & kTriadFlagAxisFlagged) ++counters_.axis_flagged;
}

void TriadCombiner::combine(const std::array<const Held*, 3>& heads, TriadBodySample* out) {
  // The first present axis stands for the stamp; its epoch is the sample's.
  const Held* lead = heads[0] ? heads[0] : heads[1] ? heads[1] : heads[2];
  out->stamp = lead->stamp;
  std::uint8_t axis_flags = 0;
  double smallest_dt = INFINITY;
  for (const Held* h : heads) {
    if (!h) continue;
    axis_flags |= h->flags;
    smallest_dt = std::min(smallest_dt, h->dt);
  }
  std::uint8_t flags = 0;
  if (axis_flags & kFlagGap) flags |= kTriadFlagGap;
  if (axis_flags & kFlagReset) flags |= kTriadFlagReset;
  if (axis_flags & (kFlagFrequencyOutOfRange | kFlagFrequencyUnknown)) flags |= kTriadFlagAxisFlagged;
  const bool all = heads[0] && heads[1] && heads[2];
  if (!all) flags |= kTriadFlagGap;
  if (all) {
    // The same interval on every axis: an axis that missed the stamp before spans two.
    const double tolerance =
        settings_.stamp_tolerance > 0.0 ? settings_.stamp_tolerance : kAutoToleranceFraction * smallest_dt;
    const bool differ01 = std::abs(heads[0]->dt - heads[1]->dt) > tolerance;
    const bool differ02 = std::abs(heads[0]->dt - heads[2]->dt) > tolerance;
    const bool differ12 = std::abs(heads[1]->dt - heads[2]->dt) > tolerance;
    if (differ01 || differ02 || differ12) {
      flags |= kTriadFlagGap;
      // The odd one out differs from both others (all three when no two agree).
      counters_.axes[0].mismatched += differ01 && differ02 ? 1 : 0;
      counters_.axes[1].mismatched += differ01 && differ12 ? 1 : 0;
      counters_.axes[2].mismatched += differ02 && differ12 ? 1 : 0;
    }
  }
  // Covariance of the rate from the axes' variances in force (also for a gap: never left unset).
  const double v0 = variance_[0], v1 = variance_[1], v2 = variance_[2];
  for (int i = 0; i < 3; ++i) {
    for (int j = i; j < 3; ++j) {
      const double c = m_(i, 0) * v0 * m_(j, 0) + m_(i, 1) * v1 * m_(j, 1) + m_(i, 2) * v2 * m_(j, 2);
      out->covariance(i, j) = c;
      out->covariance(j, i) = c;
    }
  }
  if (!(flags & (kTriadFlagGap | kTriadFlagReset))) {
    const double dt = heads[0]->dt;
    const Eigen::Vector3d dalpha(heads[0]->dalpha, heads[1]->dalpha, heads[2]->dalpha);
    const Eigen::Vector3d delta = m_ * dalpha - bias_ * dt;
    const Eigen::Vector3d rate = delta / dt;
    if (delta.allFinite() && rate.allFinite()) {
      out->dt = dt;
      out->delta_angle = delta;
      out->angular_velocity = rate;
    } else {
      flags |= kTriadFlagGap;  // an increment too large for doubles: not a measurement
      ++counters_.non_finite;
    }
  }
  if (flags & (kTriadFlagGap | kTriadFlagReset)) {
    out->delta_angle.setZero();
    out->angular_velocity.setZero();
    const Nanoseconds since = difference(out->stamp, previous_stamp_);
    out->dt = has_previous_ && previous_epoch_ == lead->epoch && since > 0 ? toSeconds(since) : smallest_dt;
  }
  out->flags = flags;
  has_previous_ = true;
  previous_stamp_ = out->stamp;
  previous_epoch_ = lead->epoch;
}

}  // namespace core
}  // namespace hrg_gyro
