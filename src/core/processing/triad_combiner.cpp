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
constexpr std::uint8_t kAllAxes = kAllTriadAxes;

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

// (rad/s)^2: a variance below this is no gyro's either (5e-324 would claim a perfect one).
constexpr double kSmallestRateVariance = 1e-20;

StampRule stampRule(const TriadCombinerSettings& s) {
  StampRule r;
  r.backward_reset = s.backward_reset;
  r.forward_jump = s.forward_jump;
  r.persist = s.jump_persist;
  return r;
}

std::array<StampTimeline, 3> makeTimelines(const TriadCombinerSettings& s) {
  const StampTimeline t(stampRule(s));
  return {{t, t, t}};
}

/// The settings checked before anything is built from them.
const TriadCombinerSettings& validated(const TriadCombinerSettings& s) {
  try {
    s.validate();
  } catch (const ConfigError& e) {
    throw std::invalid_argument(std::string("triad combiner: ") + e.what());
  }
  return s;
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
  if (!(initial_rate_variance >= kSmallestRateVariance) || !(initial_rate_variance <= kLargestRateVariance)) {
    throw ConfigError("initial_angular_velocity_variance", "must be in [1e-20, 1e12] (rad/s)^2");
  }
  if (!(max_rate > 0.0) || !std::isfinite(max_rate)) throw ConfigError("max_rate", "must be positive (rad/s)");
  if (!(backward_reset > 0.0) || !(backward_reset <= 1e9)) {
    throw ConfigError("backward_reset", "must be positive (s), at most 1e9");
  }
  if (!(forward_jump > 0.0) || !(forward_jump <= 1e9))
    throw ConfigError("forward_jump", "must be positive (s), at most 1e9");
  if (jump_persist < 1 || jump_persist > 1000) throw ConfigError("jump_persist", "must be in [1, 1000] (samples)");
}

TriadCombiner::TriadCombiner(const TriadCombinerSettings& settings, std::shared_ptr<const TriadParameters> triad)
    : settings_(validated(settings)),
      queues_{{RingBuffer<Held>(settings.max_pending), RingBuffer<Held>(settings.max_pending),
               RingBuffer<Held>(settings.max_pending)}},
      timelines_(makeTimelines(settings)) {
  max_wait_ns_ = saturatedNanoseconds(settings_.max_wait);
  staging_ = settings_.max_pending > 1;  // one sample may always wait: max_pending 1 does not let it
  variance_.fill(settings_.initial_rate_variance);
  setParameters(std::move(triad));
}

void TriadCombiner::setParameters(std::shared_ptr<const TriadParameters> triad) {
  if (!triad) throw std::invalid_argument("triad combiner: no triad parameters");
  checkFinite(*triad);
  triad_ = std::move(triad);
  m_ = triad_->axis_to_body;
  bias_ = triad_->bias;
  // M diag(v) M^T = sum_k v_k m_k m_k^T (m_k: M's column k): the outer products once per file.
  for (int k = 0; k < 3; ++k) {
    const double x = m_(0, k), y = m_(1, k), z = m_(2, k);
    outer_[k] = {{x * x, x * y, x * z, y * y, y * z, z * z}};
  }
}

bool TriadCombiner::admitUnusual(std::size_t axis, Nanoseconds stamp, StampVerdict verdict) {
  TriadAxisCounters& c = counters_.axes[axis];
  switch (verdict) {
    case StampVerdict::kNext:
    case StampVerdict::kResumedAhead:  // a gap: the stamps this axis lacks are gaps
      break;
    case StampVerdict::kNewTimeline:
      ++epoch_[axis];
      ++c.epochs;
      break;
    case StampVerdict::kNonPositive:
      ++c.bad_stamp;
      return false;
    case StampVerdict::kDuplicate:
      ++c.duplicate;
      return false;
    case StampVerdict::kBehind:
      ++c.out_of_order;
      return false;
    case StampVerdict::kJumpedBack:
    case StampVerdict::kJumpedAhead:
      ++c.stamp_jumps;
      return false;
  }
  seen_[axis] = true;
  last_stamp_[axis] = stamp;
  return true;
}

void TriadCombiner::addQueued(std::size_t axis, const Held& held, std::vector<TriadBodySample>* completed) {
  if (staging_) unstage();
  RingBuffer<Held>& queue = queues_[axis];
  // A full queue: the oldest stamps held have waited long enough.
  while (queue.size() >= settings_.max_pending) resolve(true, completed);
  queue.push_back(held);
  // While an axis has nothing, only this sample can have ended a wait: by its stamp or a full queue.
  if ((queues_[0].empty() || queues_[1].empty() || queues_[2].empty()) && !mayHaveEndedAWait(axis)) return;
  resolve(false, completed);
  staging_ =
      settings_.max_pending > 1 && queues_[0].empty() && queues_[1].empty() && queues_[2].empty() && carry_mask_ == 0;
}

void TriadCombiner::unstage() {
  for (std::size_t a = 0; a < 3; ++a) {
    if (staged_mask_ & (1u << a)) queues_[a].push_back(staged_[a]);
  }
  staged_mask_ = 0;
  staging_ = false;
}

bool TriadCombiner::mayHaveEndedAWait(std::size_t axis) const {
  if (queues_[axis].size() >= settings_.max_pending) return true;
  for (std::size_t a = 0; a < 3; ++a) {
    if (queues_[a].empty()) continue;
    const Held& h = queues_[a].front();
    if (h.epoch == epoch_[axis] && difference(last_stamp_[axis], h.stamp) > max_wait_ns_) return true;
  }
  return false;
}

void TriadCombiner::flush(std::vector<TriadBodySample>* completed) {
  unstage();
  while (!queues_[0].empty() || !queues_[1].empty() || !queues_[2].empty()) resolve(true, completed);
  staging_ = settings_.max_pending > 1;
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
    const bool awaited = nonempty != kAllAxes;  // an axis may still deliver this stamp
    if (!awaited) {
      // One clock: the three heads usually are the same instant exactly.
      const Held &h0 = queues_[0].front(), &h1 = queues_[1].front(), &h2 = queues_[2].front();
      if (h0.stamp == h1.stamp && h0.stamp == h2.stamp && h0.epoch == h1.epoch && h0.epoch == h2.epoch) {
        emit(kAllAxes, completed);
        if (force) return;
        continue;
      }
    }
    const Held& first = queues_[earliestHead()].front();
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
    if (!awaited && carryOver(present, tolerance)) continue;
    if (awaited) ++counters_.timeouts;
    emit(present, completed);
    if (force) return;  // one stamp at a time: the caller decides how far to go
  }
}

bool TriadCombiner::carryOver(std::uint8_t present, Nanoseconds tolerance) {
  if (present == kAllAxes) return false;  // nothing skipped
  std::size_t lead_axis = 0;
  while (!(present & (1u << lead_axis))) ++lead_axis;
  const Held* lead = &queues_[lead_axis].front();
  // Where the present axes' intervals began (with what was carried before): the skipping axis's
  // next interval must begin there too, one instant (within the tolerance).
  const Nanoseconds start = lead->stamp - saturatedNanoseconds(lead->dt + carry_dt_[lead_axis]);
  for (std::size_t a = 0; a < 3; ++a) {
    const Held& h = queues_[a].front();
    if (present & (1u << a)) {
      if (h.flags & (kFlagGap | kFlagReset)) return false;  // no increment to carry
      continue;
    }
    const Nanoseconds began = h.stamp - saturatedNanoseconds(h.dt);
    if (h.epoch != lead->epoch || h.flags != 0 || difference(h.stamp, lead->stamp) <= tolerance ||
        difference(began, start) > tolerance || difference(start, began) > tolerance) {
      return false;
    }
  }
  for (std::size_t a = 0; a < 3; ++a) {
    if (!(present & (1u << a))) continue;
    const Held& h = queues_[a].front();
    takeVariance(a, h);
    carry_dalpha_[a] += h.dalpha;
    carry_dt_[a] += h.dt;
    carry_mask_ |= static_cast<std::uint8_t>(1u << a);
    queues_[a].pop_front();
  }
  ++counters_.carried;
  return true;
}

void TriadCombiner::emit(std::uint8_t present, std::vector<TriadBodySample>* completed) {
  std::array<const Held*, 3> heads{{nullptr, nullptr, nullptr}};
  std::array<Held, 3> with_carry;
  for (std::size_t a = 0; a < 3; ++a) {
    if (!(present & (1u << a))) continue;
    heads[a] = &queues_[a].front();
    if (carry_mask_ & (1u << a)) {  // this axis's increments of the stamps it was carried over
      with_carry[a] = *heads[a];
      with_carry[a].dalpha += carry_dalpha_[a];
      with_carry[a].dt += carry_dt_[a];
      heads[a] = &with_carry[a];
    }
  }
  // A gap or a partial stamp after carried increments: they are not integrated (the gap's dt spans them).
  carry_mask_ = 0;
  carry_dalpha_.fill(0.0);
  carry_dt_.fill(0.0);
  emitHeads(heads, present, completed);
  for (std::size_t a = 0; a < 3; ++a) {
    if (present & (1u << a)) queues_[a].pop_front();
  }
}

void TriadCombiner::emitHeads(const std::array<const Held*, 3>& heads, std::uint8_t present,
                              std::vector<TriadBodySample>* completed) {
  const Held* lead = heads[0] ? heads[0] : heads[1] ? heads[1] : heads[2];
  if (has_previous_ &&
      (lead->epoch < previous_epoch_ || (lead->epoch == previous_epoch_ && lead->stamp <= previous_stamp_))) {
    ++counters_.late;  // its time has gone out already: the output's stamps never go back in an epoch
    return;
  }
  completed->emplace_back(TriadBodySample::Unset());
  TriadBodySample& out = completed->back();
  if (present == kAllAxes) {
    combineAligned(*heads[0], *heads[1], *heads[2], &out);
  } else {
    combinePartial(heads, &out);
  }
  out.missing_axes = static_cast<std::uint8_t>(kAllAxes & ~present);
  ++counters_.samples;
  if (out.integrated()) ++counters_.integrated;
  if (out.flags & kTriadFlagGap) ++counters_.gaps;
  if (out.flags & kTriadFlagReset) ++counters_.resets;
  if (out.flags & kTriadFlagAxisFlagged) ++counters_.axis_flagged;
  if (out.flags & kTriadFlagPrecessing) ++counters_.precessing;
}

void TriadCombiner::takeVariance(std::size_t axis, const Held& h) {
  if (h.variance >= kSmallestRateVariance && h.variance <= kLargestRateVariance) variance_[axis] = h.variance;
}

void TriadCombiner::writeCovariance(TriadBodySample* out) const {
  const double v0 = variance_[0], v1 = variance_[1], v2 = variance_[2];
  double c[6];
  for (int i = 0; i < 6; ++i) c[i] = v0 * outer_[0][i] + v1 * outer_[1][i] + v2 * outer_[2][i];
  double* m = out->covariance.data();  // symmetric: storage order does not matter
  m[0] = c[0];
  m[1] = c[1];
  m[2] = c[2];
  m[3] = c[1];
  m[4] = c[3];
  m[5] = c[4];
  m[6] = c[2];
  m[7] = c[4];
  m[8] = c[5];
}

void TriadCombiner::endSample(std::uint8_t flags, double smallest_dt, std::uint64_t epoch, TriadBodySample* out) {
  // The first sample of a new epoch: the stamps went back, and a client must restart from here.
  if (has_previous_ && epoch != previous_epoch_) flags |= kTriadFlagReset;
  if (flags & (kTriadFlagGap | kTriadFlagReset)) {
    out->delta_angle.setZero();
    out->angular_velocity.setZero();
    const Nanoseconds since = difference(out->stamp, previous_stamp_);
    out->dt = has_previous_ && previous_epoch_ == epoch && since > 0 ? toSeconds(since) : smallest_dt;
  }
  out->flags = flags;
  has_previous_ = true;
  previous_stamp_ = out->stamp;
  previous_epoch_ = epoch;
}

void TriadCombiner::combineAligned(const Held& h0, const Held& h1, const Held& h2, TriadBodySample* out) {
  takeVariance(0, h0);
  takeVariance(1, h1);
  takeVariance(2, h2);
  out->stamp = h0.stamp;  // the first axis stands for the stamp
  const std::uint8_t axis_flags = h0.flags | h1.flags | h2.flags;
  std::uint8_t flags = 0;
  if (axis_flags != 0) {
    if (axis_flags & kFlagGap) flags |= kTriadFlagGap;
    if (axis_flags & kFlagReset) flags |= kTriadFlagReset;
    if (axis_flags & (kFlagFrequencyOutOfRange | kFlagFrequencyUnknown)) flags |= kTriadFlagAxisFlagged;
    if (axis_flags & kFlagPrecessing) flags |= kTriadFlagPrecessing;
  }
  const double smallest_dt = std::min(h0.dt, std::min(h1.dt, h2.dt));
  // The same interval on every axis: an axis that missed the stamp before spans two.
  const double tolerance =
      settings_.stamp_tolerance > 0.0 ? settings_.stamp_tolerance : kAutoToleranceFraction * smallest_dt;
  const bool differ01 = std::abs(h0.dt - h1.dt) > tolerance;
  const bool differ02 = std::abs(h0.dt - h2.dt) > tolerance;
  const bool differ12 = std::abs(h1.dt - h2.dt) > tolerance;
  if (differ01 || differ02 || differ12) {
    flags |= kTriadFlagGap;
    // The odd one out differs from both others (all three when no two agree).
    counters_.axes[0].mismatched += differ01 && differ02 ? 1 : 0;
    counters_.axes[1].mismatched += differ01 && differ12 ? 1 : 0;
    counters_.axes[2].mismatched += differ02 && differ12 ? 1 : 0;
  }
  writeCovariance(out);
  if (!(flags & (kTriadFlagGap | kTriadFlagReset))) {
    const double dt = h0.dt, inverse_dt = 1.0 / dt;
    double delta[3], rate[3];
    for (int i = 0; i < 3; ++i) {
      delta[i] = (m_(i, 0) * h0.dalpha + m_(i, 1) * h1.dalpha + m_(i, 2) * h2.dalpha) - bias_(i) * dt;
      rate[i] = delta[i] * inverse_dt;
    }
    // dt is finite and positive: a finite rate has a finite increment.
    if (std::isfinite(rate[0]) && std::isfinite(rate[1]) && std::isfinite(rate[2])) {
      out->dt = dt;
      out->delta_angle << delta[0], delta[1], delta[2];
      out->angular_velocity << rate[0], rate[1], rate[2];
    } else {
      flags |= kTriadFlagGap;  // an increment too large for doubles: not a measurement
      ++counters_.non_finite;
    }
  }
  endSample(flags, smallest_dt, h0.epoch, out);
}

void TriadCombiner::combinePartial(const std::array<const Held*, 3>& heads, TriadBodySample* out) {
  // The first present axis stands for the stamp; its epoch is the sample's. Nothing integrated.
  const Held* lead = heads[0] ? heads[0] : heads[1] ? heads[1] : heads[2];
  out->stamp = lead->stamp;
  std::uint8_t flags = kTriadFlagGap;
  double smallest_dt = INFINITY;
  for (std::size_t a = 0; a < 3; ++a) {
    const Held* h = heads[a];
    if (!h) {
      ++counters_.axes[a].missing;
      continue;
    }
    takeVariance(a, *h);
    if (h->flags & kFlagReset) flags |= kTriadFlagReset;
    if (h->flags & (kFlagFrequencyOutOfRange | kFlagFrequencyUnknown)) flags |= kTriadFlagAxisFlagged;
    if (h->flags & kFlagPrecessing) flags |= kTriadFlagPrecessing;
    smallest_dt = std::min(smallest_dt, h->dt);
  }
  writeCovariance(out);
  endSample(flags, smallest_dt, lead->epoch, out);
}

}  // namespace core
}  // namespace hrg_gyro
