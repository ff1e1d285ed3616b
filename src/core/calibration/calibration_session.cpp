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

}  // namespace

CalibrationSession::CalibrationSession(const CalibrationSettings& settings, const GyroParameters& prior)
    : settings_(settings),
      prior_(prior),
      method_(makeCalibrationMethod(settings, prior)),
      detector_(settings.plateau),
      turntable_(kMaxHistory + 1),
      pending_(kMaxPending + 1) {}

void CalibrationSession::addTurntable(Nanoseconds stamp, double angle, double rate) {
  ++counters_.turntable;
  if (!turntable_.empty() && stamp <= turntable_.back().stamp) {
    ++counters_.out_of_order;
    return;
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
}

void CalibrationSession::addWave(Nanoseconds stamp, double theta, double frequency, double quadrature_ratio) {
  ++counters_.wave;
  if (std::isfinite(quadrature_ratio)) {
    quadrature_sum_ += std::abs(quadrature_ratio);
    ++quadrature_count_;
  }
  if (stamp <= last_wave_stamp_) {
    ++counters_.out_of_order;
    return;
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
  if (counters_.unsynchronized > 0) {
    o.notes.push_back(std::to_string(counters_.unsynchronized) +
                      " wave samples had no turntable state around them and were not used");
  }
  return o;
}

}  // namespace core
}  // namespace hrg_gyro
