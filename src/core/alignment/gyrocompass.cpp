#include "hrg_gyro/core/alignment/gyrocompass.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "hrg_gyro/core/alignment/gyrocompass_solver.h"
#include "hrg_gyro/core/processing/gyro_processor.h"

namespace hrg_gyro {
namespace core {
namespace {

constexpr double kDegrees = 180.0 / kPi;
constexpr double kPreWindowHorizon = 60.0;  // s of a stream kept before the window starts, beyond its length

}  // namespace

// ---------------------------------------------------------------------------------------------------
// Streams.

void Gyrocompass::BlockMotion::restart() {
  block_dt = 0.0;
  block_sum = {{0.0, 0.0, 0.0}};
  has_block = false;
}

void Gyrocompass::BlockMotion::add(double dt, const double* increment, double block) {
  block_dt += dt;
  for (std::size_t c = 0; c < channels; ++c) block_sum[c] += increment[c];
  if (block_dt < block) return;
  for (std::size_t c = 0; c < channels; ++c) {
    const double rate = block_sum[c] / block_dt;
    if (!has_block) {
      low[c] = high[c] = rate;
    } else {
      low[c] = std::min(low[c], rate);
      high[c] = std::max(high[c], rate);
    }
    worst = std::max(worst, 0.5 * (high[c] - low[c]));
  }
  has_block = true;
  block_dt = 0.0;
  block_sum = {{0.0, 0.0, 0.0}};
}

StampRule Gyrocompass::gyrocompassStampRule() {
  StampRule rule;
  rule.backward_reset = 0.5;
  rule.forward_jump = 1.0;
  rule.persist = 5;
  return rule;
}

void Gyrocompass::Stream::clear() {
  stamp.clear();
  dt.clear();
  increment.clear();
  broken.clear();
  last = 0;
  pending_break = false;
  full = false;
}

Gyrocompass::Gyrocompass(const AlignmentSettings& settings, const TriadParameters& triad)
    : settings_(settings), triad_(triad) {
  resolveNoise();
  settings_.requireComplete();
  if (!triad_.axis_to_body.allFinite() || !triad_.bias.allFinite() ||
      std::abs(triad_.axis_to_body.determinant()) < 1e-6) {
    throw std::invalid_argument("gyrocompass: the triad's matrix and bias must be finite, the matrix invertible");
  }
  if (settings_.mode == AlignmentMode::kSweep) {
    stream_count_ = 3;
    for (Stream& s : streams_) s.channels = 1;
  } else {
    streams_[0].channels = settings_.single_gyro ? 1 : 3;
  }
  if (std::abs(settings_.latitude) > settings_.max_latitude) {
    refuse(
        "latitude",
        formatAlignmentMessage(
            "latitude %.3f deg is beyond max_latitude %.3f deg: the horizontal Earth rate Omega cos(lat) = "
            "%.3g rad/s is too small for a heading",
            settings_.latitude * kDegrees, settings_.max_latitude * kDegrees, horizontalEarthRate(settings_.latitude)));
  }
}

void Gyrocompass::resolveNoise() {
  // A residual bias not given: a calibrated triad file's (its largest bias_std; all 0 is no calibration).
  GyroNoiseModel& n = settings_.noise;
  if (std::isnan(n.residual_bias) && triad_.bias_std.allFinite() && triad_.bias_std.maxCoeff() > 0.0) {
    n.residual_bias = triad_.bias_std.maxCoeff();
    settings_.noise_sources.residual_bias = "triad_file bias_std (largest axis)";
  }
}

void Gyrocompass::refuse(const std::string& gate, const std::string& reason) {
  if (!refused_gate_.empty()) return;
  refused_gate_ = gate;
  refused_reason_ = reason;
}

void Gyrocompass::abort(const std::string& reason) { refuse("aborted", reason); }

void Gyrocompass::startWindow(Nanoseconds stamp, double dt) {
  start_ = stamp - toNanoseconds(dt);
  end_ = start_ + toNanoseconds(settings_.duration);
  started_ = true;
}

void Gyrocompass::restartWindow() {
  for (Stream& s : streams_) {
    s.clear();
    s.timeline.clear();
  }
  indexer_.clear();
  accelerometer_.clear();
  for (auto& track : precession_) track.clear();
  started_ = false;
  ++restarts_;
}

bool Gyrocompass::timed(Stream* s, Nanoseconds stamp, double dt) {
  // A sample that claims more time than its stamps left it (dt beyond 1.5 times the spacing) would
  // integrate a rotation over time that was not its own: a glitch of the record, never integrated.
  if (s->last > 0 && stamp > s->last && dt > 1.5 * toSeconds(stamp - s->last)) return false;
  const StampVerdict v = s->timeline.check(stamp);
  if (v == StampVerdict::kNewTimeline) {
    restartWindow();  // the stream went back for good: a new window on its new timeline
    s->timeline.check(stamp);
    return true;
  }
  if (v == StampVerdict::kResumedAhead) s->pending_break = true;
  return stampUsable(v);
}

bool Gyrocompass::admit(Stream* s, Nanoseconds stamp, double dt, const double* increment, std::size_t channels,
                        bool gap, bool precessing) {
  if (!refused_gate_.empty() || s->full) return false;
  bool finite = stamp > 0 && std::isfinite(dt) && dt >= 1e-9 && dt <= 10.0;
  for (std::size_t c = 0; c < channels && !gap; ++c) finite = finite && std::isfinite(increment[c]);
  if (!finite || !timed(s, stamp, dt)) {
    ++dropped_;
    s->pending_break = true;
    return false;
  }
  if (!started_) {
    if (gap) return false;  // nothing to start from
    startWindow(stamp, dt);
  }
  if (stamp > end_) {
    s->full = true;
    return false;
  }
  const Nanoseconds previous = s->last;
  s->last = stamp;
  if (stamp >= end_) s->full = true;
  if (gap) {
    ++gaps_;
    s->pending_break = true;
    return false;
  }
  if (precessing) {
    refuse("motion",
           "the precession loop turned a wave during the window (FLAG_PRECESSING): its output is not "
           "the body's rate; align in the sweep mode, or when the wave rests");
    return false;
  }
  const Nanoseconds begin = stamp - toNanoseconds(dt);
  if (begin < start_) {  // began before the window (another stream started it)
    s->pending_break = true;
    return false;
  }
  // A sample that does not start where the previous one ended (samples lost in between) breaks the angle.
  const bool broken = s->stamp.empty() || s->pending_break || std::abs(toSeconds(begin - previous)) > 0.5 * dt;
  s->pending_break = false;
  s->stamp.push_back(stamp);
  s->dt.push_back(dt);
  for (std::size_t c = 0; c < channels; ++c) s->increment.push_back(increment[c]);
  s->broken.push_back(broken ? 1 : 0);
  return true;
}

void Gyrocompass::addTriad(const TriadBodySample& sample) {
  if (settings_.mode == AlignmentMode::kSweep || settings_.single_gyro) {
    throw std::invalid_argument(
        "gyrocompass: triad samples are not this mode's input (sweep: addSweepAxis; one "
        "gyro: addAxis)");
  }
  const double increment[3] = {sample.delta_angle.x(), sample.delta_angle.y(), sample.delta_angle.z()};
  admit(&streams_[0], sample.stamp, sample.dt, increment, 3, !sample.integrated(),
        (sample.flags & kTriadFlagPrecessing) != 0);
}

void Gyrocompass::addAxis(const AxisOutput& output) {
  if (!settings_.single_gyro) throw std::invalid_argument("gyrocompass: one gyro's outputs need single_gyro");
  admit(&streams_[0], output.stamp, output.dt, &output.dalpha, 1, (output.flags & (kFlagGap | kFlagReset)) != 0,
        (output.flags & kFlagPrecessing) != 0);
}

void Gyrocompass::addSweepAxis(std::size_t axis, const AxisOutput& output) {
  if (settings_.mode != AlignmentMode::kSweep) throw std::invalid_argument("gyrocompass: not the sweep mode");
  if (axis >= 3) throw std::out_of_range("gyrocompass: axis index must be 0, 1 or 2");
  admit(&streams_[axis], output.stamp, output.dt, &output.dalpha, 1, (output.flags & (kFlagGap | kFlagReset)) != 0,
        false);
}

template <typename Record>
bool Gyrocompass::takeRecord(StampTimeline* timeline, std::vector<Record>* records, Nanoseconds stamp) {
  const StampVerdict v = timeline->check(stamp);
  if (v == StampVerdict::kNewTimeline) records->clear();
  if (!stampUsable(v)) return false;
  // Records older than the window are nobody's: memory stays flat however long the stream ran before
  // it. Before the window starts (no gyro sample yet: hrg_bag align --start skipping minutes of them,
  // or a caller feeding one stream whole before the gyros), only the last window's length plus
  // kPreWindowHorizon s of this stream are kept: the gyros may lag it by that much.
  // (Trimmed a horizon at a time, not at every record: the erase moves what is kept.)
  const Nanoseconds keep_after = stamp - toNanoseconds(settings_.duration + kPreWindowHorizon);
  const Nanoseconds oldest = started_ ? start_ - toNanoseconds(1.0) : keep_after;
  const Nanoseconds trim_below = started_ ? oldest : keep_after - toNanoseconds(kPreWindowHorizon);
  if (records->size() >= 4096 && records->front().stamp < trim_below) {
    const auto keep = std::lower_bound(records->begin(), records->end(), oldest,
                                       [](const Record& r, Nanoseconds t) { return r.stamp < t; });
    records->erase(records->begin(), keep);
  }
  return true;
}

bool Gyrocompass::beforeWindow(Nanoseconds stamp) const { return started_ && stamp < start_ - toNanoseconds(1.0); }

void Gyrocompass::addPrecession(std::size_t axis, const PrecessionStateRecord& record) {
  if (axis >= 3) throw std::out_of_range("gyrocompass: axis index must be 0, 1 or 2");
  if (record.stamp <= 0 || !std::isfinite(record.rate) || !std::isfinite(record.angle) ||
      !takeRecord(&precession_time_[axis], &precession_[axis], record.stamp)) {
    ++dropped_;
    return;
  }
  if (!beforeWindow(record.stamp)) precession_[axis].push_back(record);
}

void Gyrocompass::addIndexer(const IndexerRecord& record) {
  if (record.stamp <= 0 || !std::isfinite(record.angle) || std::isinf(record.rate) ||
      !takeRecord(&indexer_time_, &indexer_, record.stamp)) {
    ++dropped_;
    return;
  }
  if (!beforeWindow(record.stamp)) indexer_.push_back(record);
}

void Gyrocompass::addAccelerometer(const AccelerometerRecord& record) {
  if (record.stamp <= 0 || !record.specific_force.allFinite() ||
      !takeRecord(&accelerometer_time_, &accelerometer_, record.stamp)) {
    ++dropped_;
    return;
  }
  if (!beforeWindow(record.stamp)) accelerometer_.push_back(record);
}

bool Gyrocompass::complete() const {
  if (!refused_gate_.empty()) return true;
  for (std::size_t i = 0; i < stream_count_; ++i) {
    if (!streams_[i].full) return false;
  }
  return true;
}

AlignmentProgress Gyrocompass::progress() const {
  AlignmentProgress p;
  p.duration = settings_.duration;
  p.complete = complete();
  p.refused = !refused_gate_.empty();
  p.reason = refused_reason_;
  if (started_) {
    Nanoseconds newest = start_;
    for (std::size_t i = 0; i < stream_count_; ++i) newest = std::max(newest, streams_[i].last);
    p.seconds = std::min(toSeconds(newest - start_), settings_.duration);
  }
  p.samples = streams_[0].stamp.size();
  p.gaps = gaps_;
  p.dropped = dropped_;
  p.restarts = restarts_;
  p.indexer = indexer_.size();
  p.accelerometer = accelerometer_.size();
  for (const auto& track : precession_) p.precession += track.size();
  p.held = p.indexer + p.accelerometer + p.precession;
  return p;
}

}  // namespace core
}  // namespace hrg_gyro
