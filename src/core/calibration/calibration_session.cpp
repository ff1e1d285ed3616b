#include "hrg_gyro/core/calibration/calibration_session.h"

#include <algorithm>

namespace hrg_gyro {
namespace core {
namespace {

// The two streams reach a live calibrator through different queues and, under accelerated sim time,
// may be tens of seconds of data apart: wave samples wait up to kMaxWait for the turntable stream,
// and turntable history reaches kMaxWait back from both streams' newest stamps. Both buffers are
// bounded by count as well, so memory stays constant whatever happens.
constexpr double kMaxWait = 60.0;  // s of stamps
constexpr std::size_t kMaxPending = 200000;
constexpr std::size_t kMaxHistory = 400000;
// rad: the angle a good record may differ from the last good one beyond max_rate * dt (reporting
// jitter between the angle and the stamp).
constexpr double kAngleSlack = 0.01;

}  // namespace

CalibrationSession::CalibrationSession(const CalibrationSettings& settings, const GyroParameters& prior)
    : settings_(settings),
      prior_(prior),
      method_(makeCalibrationMethod(settings, prior)),
      detector_(settings.plateau),
      turntable_(kMaxHistory + 1),
      pending_(kMaxPending + 1),
      turntable_timeline_(settings.backward_reset, settings.backward_persist),
      wave_timeline_(settings.backward_reset, settings.backward_persist) {}

bool CalibrationSession::plausible(Nanoseconds stamp, double angle, double rate) {
  if (!std::isfinite(rate) || std::abs(rate) > settings_.plateau.max_rate) {
    ++counters_.rejected.bad_rate;
    return false;
  }
  if (!std::isfinite(angle)) {
    ++counters_.rejected.bad_angle;
    return false;
  }
  if (!turntable_.empty() && stamp > turntable_.back().stamp) {
    const TurntableRecord& last = turntable_.back();
    const double reach = settings_.plateau.max_rate * toSeconds(stamp - last.stamp) + kAngleSlack;
    // A few in a row: a glitch. More than backward_persist: the table's angle really is elsewhere
    // (the good record kept last was the glitch, or the encoder was re-zeroed); take the new one.
    if (std::abs(angle - last.angle) > reach && ++bad_angle_run_ <= settings_.backward_persist) {
      ++counters_.rejected.bad_angle;
      return false;
    }
  }
  bad_angle_run_ = 0;
  return true;
}

bool CalibrationSession::addTurntable(Nanoseconds stamp, double angle, double rate) {
  ++counters_.turntable;
  ++counters_.turntable_total;
  // Values first: a glitched record must not move the stamp reference either.
  if (stamp > 0 && !plausible(stamp, angle, rate)) return false;
  switch (turntable_timeline_.check(stamp)) {
    case StampVerdict::kNext:
      break;
    case StampVerdict::kNewTimeline:
      restart();
      wave_timeline_.expectJumpBack(kMaxWait);
      counters_.turntable = 1;
      break;
    case StampVerdict::kNonPositive:
      ++counters_.rejected.bad_stamp;
      return false;
    case StampVerdict::kDuplicate:
      ++counters_.rejected.duplicate;
      return false;
    case StampVerdict::kBehind:
      ++counters_.rejected.out_of_order;
      return false;
  }
  turntable_.push_back({stamp, angle, rate, detector_.update(stamp, rate)});
  drain();
  // Keep history for waiting samples and for wave samples that lag behind this stream.
  Nanoseconds keep_from = std::min(stamp, last_wave_stamp_ > 0 ? last_wave_stamp_ : stamp);
  if (!pending_.empty()) keep_from = std::min(keep_from, pending_.front().stamp);
  keep_from -= toNanoseconds(kMaxWait);
  while (turntable_.size() > 2 && (turntable_[1].stamp < keep_from || turntable_.size() > kMaxHistory)) {
    turntable_.pop_front();
  }
  return true;
}

void CalibrationSession::restart() {
  const TurntableRejects rejected = counters_.rejected;
  const std::uint64_t restarts = counters_.restarts + 1;
  const std::uint64_t out_of_order = counters_.out_of_order;
  const std::uint64_t turntable_total = counters_.turntable_total;
  method_ = makeCalibrationMethod(settings_, prior_);
  detector_ = PlateauDetector(settings_.plateau);
  turntable_.clear();
  pending_.clear();
  counters_ = SessionCounters();
  counters_.rejected = rejected;
  counters_.restarts = restarts;
  counters_.out_of_order = out_of_order;
  counters_.turntable_total = turntable_total;
  bad_angle_run_ = 0;
  last_wave_stamp_ = 0;
  last_generator_stamp_ = 0;
  generator_ended_ = false;
  quadrature_sum_ = 0.0;
  quadrature_count_ = 0;
}

void CalibrationSession::addWave(Nanoseconds stamp, double theta, double frequency, double quadrature_ratio) {
  ++counters_.wave;
  switch (wave_timeline_.check(stamp)) {
    case StampVerdict::kNext:
      break;
    case StampVerdict::kNewTimeline:
      restart();
      turntable_timeline_.expectJumpBack(kMaxWait);
      counters_.wave = 1;
      break;
    default:
      ++counters_.out_of_order;
      return;
  }
  if (std::isfinite(quadrature_ratio)) {
    quadrature_sum_ += std::abs(quadrature_ratio);
    ++quadrature_count_;
  }
  last_wave_stamp_ = stamp;
  pending_.push_back({stamp, theta, frequency});
  // A turntable stream that stopped (or never started) must not make the queue grow without bound.
  while (!pending_.empty() && (pending_.size() > kMaxPending || toSeconds(stamp - pending_.front().stamp) > kMaxWait)) {
    ++counters_.unsynchronized;
    pending_.pop_front();
  }
  drain();
}

void CalibrationSession::generatorSweepEnded() { generator_ended_ = last_generator_stamp_ > 0; }

void CalibrationSession::addGeneratorPair(Nanoseconds stamp, const ChannelVector& raw, const ChannelVector& reference) {
  last_generator_stamp_ = std::max(last_generator_stamp_, stamp);
  method_->addGeneratorPair(raw, reference);
  ++counters_.used;
}

void CalibrationSession::drain() {
  while (!pending_.empty() && !turntable_.empty() && pending_.front().stamp <= turntable_.back().stamp) {
    classify(pending_.front());
    pending_.pop_front();
  }
}

void CalibrationSession::classify(const WaveRecord& w) {
  // The last state at or before the sample and the first at or after it.
  const std::size_t after =
      turntable_.lowerBound(w.stamp, [](const TurntableRecord& r, Nanoseconds t) { return r.stamp < t; });
  if (after == turntable_.size() || (after == 0 && turntable_[0].stamp != w.stamp)) {
    ++counters_.unsynchronized;
    return;
  }
  const TurntableRecord& b = turntable_[after];
  const TurntableRecord& a = b.stamp == w.stamp ? b : turntable_[after - 1];
  if (toSeconds(b.stamp - a.stamp) > settings_.plateau.max_gap) {
    ++counters_.unsynchronized;
    return;
  }
  if (a.plateau.id != b.plateau.id || !a.plateau.settled) {
    ++counters_.unsettled;
    return;
  }
  PlateauSample s;
  s.stamp = w.stamp;
  s.theta = w.theta;
  s.frequency = w.frequency;
  s.plateau = b.plateau;
  const double span = toSeconds(b.stamp - a.stamp);
  const double f = span > 0.0 ? toSeconds(w.stamp - a.stamp) / span : 0.0;
  s.table_angle = a.angle + f * (b.angle - a.angle);
  s.table_rate = a.rate + f * (b.rate - a.rate);
  method_->addSample(s);
  ++counters_.used;
}

bool CalibrationSession::shouldFinish() const {
  if (settings_.auto_finish_idle <= 0.0 || !method_->complete()) return false;
  if (traitsOf(settings_.method).uses_generator_pairs) return generator_ended_;
  if (turntable_.empty()) return false;
  const TurntableRecord& last = turntable_.back();
  return last.plateau.is_static && toSeconds(last.stamp - last.plateau.start) >= settings_.auto_finish_idle;
}

CalibrationOutcome CalibrationSession::finish() const {
  CalibrationOutcome o = method_->finish(prior_);
  o.quadrature_ratio = quadrature_count_ > 0 ? quadrature_sum_ / quadrature_count_ : 0.0;
  diagnose(&o, prior_.correction);
  o.turntable_records = counters_.turntable_total;
  o.turntable_rejected = counters_.rejected;
  o.restarts = counters_.restarts;
  if (counters_.rejected.total() > 0) {
    const TurntableRejects& r = counters_.rejected;
    o.notes.push_back(std::to_string(r.total()) + " glitched turntable records dropped (" + std::to_string(r.bad_rate) +
                      " bad rate, " + std::to_string(r.bad_angle) + " bad angle, " + std::to_string(r.bad_stamp) +
                      " zero stamp, " + std::to_string(r.duplicate) + " duplicate, " + std::to_string(r.out_of_order) +
                      " out of order)");
  }
  if (counters_.restarts > 0) {
    o.notes.push_back("the stamps went back for good " + std::to_string(counters_.restarts) +
                      " time(s) (bag loop): the run restarted from the prior");
  }
  if (counters_.unsynchronized > 0) {
    o.notes.push_back(std::to_string(counters_.unsynchronized) +
                      " wave samples had no turntable state around them and were not used");
  }
  return o;
}

}  // namespace core
}  // namespace hrg_gyro
