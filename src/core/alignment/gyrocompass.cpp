#include "hrg_gyro/core/alignment/gyrocompass.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "hrg_gyro/core/alignment/gyrocompass_solver.h"
#include "hrg_gyro/core/alignment/motion_gate.h"
#include "hrg_gyro/core/common/number_format.h"
#include "hrg_gyro/core/model/earth_rate.h"
#include "hrg_gyro/core/processing/gyro_processor.h"

namespace hrg_gyro {
namespace core {
namespace {

constexpr double kDegrees = 180.0 / kPi;
constexpr double kPreWindowHorizon = 60.0;  // s of a stream kept before the window starts, beyond its length

}  // namespace

// ---------------------------------------------------------------------------------------------------
// Streams.

StampRule Gyrocompass::gyrocompassStampRule() {
  StampRule rule;
  rule.backward_reset = 0.5;
  rule.forward_jump = 1.0;
  rule.persist = 5;
  return rule;
}

Gyrocompass::Gyrocompass(const AlignmentSettings& settings, const TriadParameters& triad) : settings_(settings) {
  records_.triad = triad;
  resolveNoise();
  settings_.requireComplete();
  if (!triad.axis_to_body.allFinite() || !triad.bias.allFinite() || std::abs(triad.axis_to_body.determinant()) < 1e-6) {
    throw std::invalid_argument("gyrocompass: the triad's matrix and bias must be finite, the matrix invertible");
  }
  if (settings_.mode == AlignmentMode::kSweep) {
    records_.stream_count = 3;
    for (GyroStreamRecords& s : records_.streams) s.channels = 1;
  } else {
    records_.streams[0].channels = settings_.single_gyro ? 1 : 3;
  }
  if (std::abs(settings_.latitude) > settings_.max_latitude) {
    refuse(
        "latitude",
        formatNumbers("latitude %.3f deg is beyond max_latitude %.3f deg: the horizontal Earth rate Omega cos(lat) = "
                      "%.3g rad/s is too small for a heading",
                      settings_.latitude * kDegrees, settings_.max_latitude * kDegrees,
                      horizontalEarthRate(settings_.latitude)));
  }
}

void Gyrocompass::resolveNoise() {
  // A residual bias not given: a calibrated triad file's (its largest bias_std; all 0 is no calibration).
  GyroNoiseModel& n = settings_.noise;
  const TriadParameters& triad = records_.triad;
  if (std::isnan(n.residual_bias) && triad.bias_std.allFinite() && triad.bias_std.maxCoeff() > 0.0) {
    n.residual_bias = triad.bias_std.maxCoeff();
    settings_.noise_sources.residual_bias = "triad_file bias_std (largest axis)";
  }
}

void Gyrocompass::refuse(const std::string& gate, const std::string& reason) {
  if (!records_.refused_gate.empty()) return;
  records_.refused_gate = gate;
  records_.refused_reason = reason;
}

void Gyrocompass::abort(const std::string& reason) { refuse("aborted", reason); }

void Gyrocompass::startWindow(Nanoseconds stamp, double dt) {
  records_.start = stamp - toNanoseconds(dt);
  records_.end = records_.start + toNanoseconds(settings_.duration);
  records_.started = true;
}

void Gyrocompass::restartWindow() {
  records_.clearWindow();
  for (StreamIntake& s : intake_) {
    s.pending_break = false;
    s.full = false;
    s.timeline.clear();
  }
  ++restarts_;
}

bool Gyrocompass::timed(std::size_t stream, Nanoseconds stamp, double dt) {
  const Nanoseconds last = records_.streams[stream].last;
  StreamIntake* s = &intake_[stream];
  // A sample that claims more time than its stamps left it (dt beyond 1.5 times the spacing) would
  // integrate a rotation over time that was not its own: a glitch of the record, never integrated.
  if (last > 0 && stamp > last && dt > 1.5 * toSeconds(stamp - last)) return false;
  const StampVerdict v = s->timeline.check(stamp);
  if (v == StampVerdict::kNewTimeline) {
    restartWindow();  // the stream went back for good: a new window on its new timeline
    s->timeline.check(stamp);
    return true;
  }
  if (v == StampVerdict::kResumedAhead) s->pending_break = true;
  return stampUsable(v);
}

bool Gyrocompass::admit(std::size_t stream, Nanoseconds stamp, double dt, const double* increment, std::size_t channels,
                        bool gap, bool precessing) {
  GyroStreamRecords* r = &records_.streams[stream];
  StreamIntake* s = &intake_[stream];
  if (!records_.refused_gate.empty() || s->full) return false;
  bool finite = stamp > 0 && std::isfinite(dt) && dt >= 1e-9 && dt <= 10.0;
  for (std::size_t c = 0; c < channels && !gap; ++c) finite = finite && std::isfinite(increment[c]);
  if (!finite || !timed(stream, stamp, dt)) {
    ++dropped_;
    s->pending_break = true;
    return false;
  }
  if (!records_.started) {
    if (gap) return false;  // nothing to start from
    startWindow(stamp, dt);
  }
  if (stamp > records_.end) {
    s->full = true;
    return false;
  }
  const Nanoseconds previous = r->last;
  r->last = stamp;
  if (stamp >= records_.end) s->full = true;
  if (gap) {
    ++gaps_;
    s->pending_break = true;
    return false;
  }
  if (precessing) {
    refuse(kMotionGate, commandedWaveProblem());
    return false;
  }
  const Nanoseconds begin = stamp - toNanoseconds(dt);
  if (begin < records_.start) {  // began before the window (another stream started it)
    s->pending_break = true;
    return false;
  }
  // A sample that does not start where the previous one ended (samples lost in between) breaks the angle.
  const bool broken = r->stamp.empty() || s->pending_break || std::abs(toSeconds(begin - previous)) > 0.5 * dt;
  s->pending_break = false;
  r->stamp.push_back(stamp);
  r->dt.push_back(dt);
  for (std::size_t c = 0; c < channels; ++c) r->increment.push_back(increment[c]);
  r->broken.push_back(broken ? 1 : 0);
  return true;
}

void Gyrocompass::addTriad(const TriadBodySample& sample) {
  if (settings_.mode == AlignmentMode::kSweep || settings_.single_gyro) {
    throw std::invalid_argument(
        "gyrocompass: triad samples are not this mode's input (sweep: addSweepAxis; one "
        "gyro: addAxis)");
  }
  const double increment[3] = {sample.delta_angle.x(), sample.delta_angle.y(), sample.delta_angle.z()};
  admit(0, sample.stamp, sample.dt, increment, 3, !sample.integrated(), (sample.flags & kTriadFlagPrecessing) != 0);
}

void Gyrocompass::addAxis(const AxisOutput& output) {
  if (!settings_.single_gyro) throw std::invalid_argument("gyrocompass: one gyro's outputs need single_gyro");
  admit(0, output.stamp, output.dt, &output.dalpha, 1, (output.flags & (kFlagGap | kFlagReset)) != 0,
        (output.flags & kFlagPrecessing) != 0);
}

void Gyrocompass::addSweepAxis(std::size_t axis, const AxisOutput& output) {
  if (settings_.mode != AlignmentMode::kSweep) throw std::invalid_argument("gyrocompass: not the sweep mode");
  if (axis >= 3) throw std::out_of_range("gyrocompass: axis index must be 0, 1 or 2");
  admit(axis, output.stamp, output.dt, &output.dalpha, 1, (output.flags & (kFlagGap | kFlagReset)) != 0, false);
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
  const Nanoseconds oldest = records_.started ? records_.start - toNanoseconds(1.0) : keep_after;
  const Nanoseconds trim_below = records_.started ? oldest : keep_after - toNanoseconds(kPreWindowHorizon);
  if (records->size() >= 4096 && records->front().stamp < trim_below) {
    const auto keep = std::lower_bound(records->begin(), records->end(), oldest,
                                       [](const Record& r, Nanoseconds t) { return r.stamp < t; });
    records->erase(records->begin(), keep);
  }
  return true;
}

bool Gyrocompass::beforeWindow(Nanoseconds stamp) const {
  return records_.started && stamp < records_.start - toNanoseconds(1.0);
}

void Gyrocompass::addPrecession(std::size_t axis, const PrecessionStateRecord& record) {
  if (axis >= 3) throw std::out_of_range("gyrocompass: axis index must be 0, 1 or 2");
  if (record.stamp <= 0 || !std::isfinite(record.rate) || !std::isfinite(record.angle) ||
      !takeRecord(&precession_time_[axis], &records_.precession[axis], record.stamp)) {
    ++dropped_;
    return;
  }
  if (!beforeWindow(record.stamp)) records_.precession[axis].push_back(record);
}

void Gyrocompass::addIndexer(const IndexerRecord& record) {
  if (record.stamp <= 0 || !std::isfinite(record.angle) || std::isinf(record.rate) ||
      !takeRecord(&indexer_time_, &records_.indexer, record.stamp)) {
    ++dropped_;
    return;
  }
  if (!beforeWindow(record.stamp)) records_.indexer.push_back(record);
}

void Gyrocompass::addAccelerometer(const AccelerometerRecord& record) {
  if (record.stamp <= 0 || !record.specific_force.allFinite() ||
      !takeRecord(&accelerometer_time_, &records_.accelerometer, record.stamp)) {
    ++dropped_;
    return;
  }
  if (!beforeWindow(record.stamp)) records_.accelerometer.push_back(record);
}

bool Gyrocompass::complete() const {
  if (!records_.refused_gate.empty()) return true;
  for (std::size_t i = 0; i < records_.stream_count; ++i) {
    if (!intake_[i].full) return false;
  }
  return true;
}

AlignmentResult Gyrocompass::finish() const { return GyrocompassSolver(settings_, records_).solve(); }

AlignmentProgress Gyrocompass::progress() const {
  AlignmentProgress p;
  p.duration = settings_.duration;
  p.complete = complete();
  p.refused = !records_.refused_gate.empty();
  p.reason = records_.refused_reason;
  if (records_.started) {
    const Nanoseconds newest = std::max(records_.start, records_.lastSample());
    p.seconds = std::min(records_.seconds(newest), settings_.duration);
  }
  p.samples = records_.streams[0].stamp.size();
  p.gaps = gaps_;
  p.dropped = dropped_;
  p.restarts = restarts_;
  p.indexer = records_.indexer.size();
  p.accelerometer = records_.accelerometer.size();
  for (const auto& track : records_.precession) p.precession += track.size();
  p.held = p.indexer + p.accelerometer + p.precession;
  return p;
}

}  // namespace core
}  // namespace hrg_gyro
