#include "hrg_gyro/core/processing/precession_watch.h"

#include <string>

#include "hrg_gyro/core/common/number_format.h"
#include "hrg_gyro/core/common/yaml_field.h"

namespace hrg_gyro {
namespace core {

const char* toString(PrecessionVerdict verdict) {
  switch (verdict) {
    case PrecessionVerdict::kNoState:
      return "no precession state";
    case PrecessionVerdict::kStill:
      return "not precessed";
    case PrecessionVerdict::kPrecessing:
      return "precessed on command";
    case PrecessionVerdict::kUnknown:
      return "precession state unknown";
  }
  return "unknown verdict";
}

void PrecessionWatchSettings::validate() const {
  if (!(std::isfinite(hold) && hold > 0.0)) {
    throw ConfigError("precession_hold", "must be a positive number of seconds, got " + formatDouble(hold));
  }
  if (!(std::isfinite(backward_reset) && backward_reset > 0.0)) {
    throw ConfigError("backward_reset", "must be a positive number of seconds, got " + formatDouble(backward_reset));
  }
  if (max_held < 1) throw ConfigError("max_held", "must be at least 1");
}

PrecessionWatch::PrecessionWatch(const PrecessionWatchSettings& settings)
    : settings_((settings.validate(), settings)),
      hold_ns_(toNanoseconds(settings.hold)),
      backward_reset_ns_(toNanoseconds(settings.backward_reset)),
      states_(settings.max_held),
      // next() decides the oldest once more than max_held wait; room beyond for the caller's add.
      outputs_(2 * settings.max_held + 1) {}

bool PrecessionWatch::addState(const PrecessionStateRecord& record) {
  if (!(record.stamp > 0) || !std::isfinite(record.rate) || !std::isfinite(record.angle)) {
    ++counters_.dropped_states;
    return false;
  }
  if (awaiting_state_jump_) {
    // The outputs went back; a record far ahead of them is the old timeline's, still in transit.
    if (record.stamp > newest_to_ + backward_reset_ns_) {
      ++counters_.dropped_states;
      return false;
    }
    awaiting_state_jump_ = false;
    has_state_stamp_ = false;
  }
  if (has_state_stamp_ && record.stamp <= last_state_stamp_) {
    if (last_state_stamp_ - record.stamp <= backward_reset_ns_) {
      ++counters_.dropped_states;  // a duplicate or out-of-order record
      return false;
    }
    // The stream went back for good: what waits is decided with the old timeline's records.
    decideWaiting();
    states_.clear();
    decided_to_ = 0;
    ++counters_.timelines;
  }
  if (states_.size() >= settings_.max_held) states_.pop_front();
  states_.push_back(record);
  last_state_stamp_ = record.stamp;
  has_state_stamp_ = true;
  seen_state_ = true;
  ++counters_.states;
  if (outputs_.empty()) trim(decided_to_);
  return true;
}

void PrecessionWatch::addOutput(Nanoseconds from, Nanoseconds to) {
  if (has_output_ && to <= newest_to_) {
    // The processor's stamps went back (it reset): a new timeline.
    decideWaiting();
    ++counters_.timelines;
    decided_to_ = 0;
    if (!states_.empty() && states_.back().stamp > to + backward_reset_ns_) {
      // The state stream has not gone back yet: its records are the old timeline's. The stream is
      // taken to stand at `to` until it does, so that one that never does is a stalled stream.
      states_.clear();
      awaiting_state_jump_ = true;
      last_state_stamp_ = to;
      has_state_stamp_ = true;
    }
  }
  outputs_.push_back({from, to, false, PrecessionDecision()});
  newest_to_ = to;
  has_output_ = true;
}

bool PrecessionWatch::next(PrecessionDecision* decision) {
  if (outputs_.empty()) return false;
  Waiting& w = outputs_[0];
  const bool early = w.decided;
  if (!early) {
    const bool reached = !states_.empty() && states_.back().stamp >= w.to;
    const bool stalled = has_state_stamp_ && newest_to_ - last_state_stamp_ > hold_ns_;
    if (!(finished_ || !seen_state_ || reached || stalled || outputs_.size() > settings_.max_held)) return false;
    w.decision = decide(w.from, w.to);
  }
  *decision = w.decision;
  ++counters_.decided;
  if (decision->verdict == PrecessionVerdict::kPrecessing) ++counters_.precessing;
  if (decision->verdict == PrecessionVerdict::kUnknown) ++counters_.unknown;
  // Only an output the records decided moves the records' trim point: one decided as its timeline
  // ended, or as unknown, may lie on the other timeline, whose records must stay.
  if (!early &&
      (decision->verdict == PrecessionVerdict::kStill || decision->verdict == PrecessionVerdict::kPrecessing)) {
    decided_to_ = w.to;
  }
  outputs_.pop_front();
  trim(decided_to_);
  return true;
}

void PrecessionWatch::finish() { finished_ = true; }

PrecessionDecision PrecessionWatch::decide(Nanoseconds from, Nanoseconds to) const {
  PrecessionDecision d;
  if (!seen_state_) return d;  // kNoState
  if (states_.empty() || states_.back().stamp < to) {
    d.verdict = PrecessionVerdict::kUnknown;
    return d;
  }
  const auto at_or_before = [](const PrecessionStateRecord& r, Nanoseconds t) { return r.stamp <= t; };
  const std::size_t upto_from = states_.lowerBound(from, at_or_before);  // records at or before `from`
  const std::size_t upto_to = states_.lowerBound(to, at_or_before);
  if (upto_to == 0) {
    // Every record lies after the interval (the stream began later): the first one's rate was in
    // force when it began, perhaps earlier.
    d.rate = states_[0].rate;
    d.verdict = d.rate != 0.0 ? PrecessionVerdict::kPrecessing : PrecessionVerdict::kStill;
    return d;
  }
  // The record in force at `from` (or the first inside the interval) through the last at or before `to`.
  const std::size_t begin = upto_from > 0 ? upto_from - 1 : 0;
  const std::size_t end = upto_to - 1;
  bool precessed = states_[end].angle != states_[begin].angle;
  for (std::size_t i = begin; i <= end && !precessed; ++i) precessed = states_[i].rate != 0.0;
  d.rate = states_[end].rate;
  d.verdict = precessed ? PrecessionVerdict::kPrecessing : PrecessionVerdict::kStill;
  return d;
}

void PrecessionWatch::decideWaiting() {
  for (std::size_t i = 0; i < outputs_.size(); ++i) {
    Waiting& w = outputs_[i];
    if (w.decided) continue;
    w.decision = decide(w.from, w.to);
    w.decided = true;
  }
}

void PrecessionWatch::trim(Nanoseconds upto) {
  while (states_.size() >= 2 && states_[1].stamp <= upto) states_.pop_front();
}

}  // namespace core
}  // namespace hrg_gyro
