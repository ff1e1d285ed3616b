#include "hrg_gyro/core/calibration/calibration_feed.h"

#include "hrg_gyro/core/model/calibration_method_kind.h"
#include "hrg_gyro/core/model/wave_parameters.h"

namespace hrg_gyro {
namespace core {

CalibrationFeed::CalibrationFeed(CalibrationSession* session, GyroProcessor* processor, bool watch_finish)
    : processor_(processor),
      watch_finish_(watch_finish),
      pairing_([this](Nanoseconds t, const ChannelVector& raw, const ChannelVector& reference) {
        session_->addGeneratorPair(t, raw, reference);
      }) {
  startRun(session);
}

void CalibrationFeed::startRun(CalibrationSession* session) {
  session_ = session;
  const CalibrationMethodTraits* traits = session ? &traitsOf(session->settings().method) : nullptr;
  pairs_ = traits && traits->uses_generator_pairs;
  virtual_rotation_ = traits && traits->virtual_rotation;
  forgetRun();
}

void CalibrationFeed::forgetRun() {
  pairing_.clear();
  sweep_end_ = last_channels_ = 0;
  last_rotation_ = 0;
  waves_reached_rotation_ = true;
  finish_pending_ = false;
  newest_wave_ = last_taken_wave_ = 0;
}

std::uint64_t CalibrationFeed::droppedWaves() const {
  return session_->counters().wave_jumps + session_->counters().out_of_order;
}

void CalibrationFeed::noteRestart(std::uint64_t restarts_before, FeedStep* step) {
  if (session_->counters().restarts == restarts_before) return;
  step->restarted = true;
  forgetRun();
}

FeedStep CalibrationFeed::addChannels(const ChannelSample& in) {
  if (!session_) return {};
  if (!pairs_) return addWaveChannels(in, in.stamp);
  last_channels_ = in.stamp;
  pairing_.addRaw(in.stamp, in.z);
  if (sweep_end_ != 0 && in.stamp >= sweep_end_) return endSweep();
  return {};
}

FeedStep CalibrationFeed::addWaveChannels(const ChannelSample& in, Nanoseconds wave_stamp) {
  if (!session_ || !processor_) return {};
  const ProcessorResult r = processor_->process(in);
  if (!r.has_wave) return {};
  return addWaveRecord(wave_stamp, r.wave.theta, in.frequency, quadratureRatio(r.wave.quadrature, r.wave.amplitude));
}

FeedStep CalibrationFeed::addSweepSample(Nanoseconds stamp, const ChannelVector& raw, const WaveParameters& reference) {
  if (!session_) return {};
  pairing_.addRaw(stamp, raw);
  pairing_.addReference(stamp, reference);
  return {};
}

FeedStep CalibrationFeed::addWave(Nanoseconds stamp, double theta, double frequency, double quadrature_ratio) {
  if (!session_) return {};
  return addWaveRecord(stamp, theta, frequency, quadrature_ratio);
}

FeedStep CalibrationFeed::addWaveRecord(Nanoseconds stamp, double theta, double frequency, double quadrature_ratio) {
  FeedStep step;
  if (stamp > newest_wave_) newest_wave_ = stamp;
  const std::uint64_t restarts = session_->counters().restarts;
  const std::uint64_t dropped = droppedWaves();
  session_->addWave(stamp, theta, frequency, quadrature_ratio);
  noteRestart(restarts, &step);
  if (!step.restarted && droppedWaves() != dropped) return step;  // a glitch says nothing of the waves' progress
  last_taken_wave_ = stamp;
  // The auto-finish rule needs both streams: the rest seen in the rotation records and the data
  // complete from the waves. The waves come later than the records (a hop more through the processor,
  // later still on a busy host), so the rule is checked again when they reach the latest record's
  // stamp, and a run the rule ends on a record finishes only when the waves reach it.
  if (!watch_finish_ || waves_reached_rotation_ || stamp < last_rotation_) return step;
  waves_reached_rotation_ = true;
  step.should_finish = session_->shouldFinish();
  return step;
}

FeedStep CalibrationFeed::addTableState(Nanoseconds stamp, double angle, double rate, std::uint64_t sequence) {
  if (!session_ || virtual_rotation_) return {};
  if (sweep_end_ != 0 && stamp - sweep_end_ > toNanoseconds(kSweepChannelsWait)) {
    // The raw channels have not reached the end of the sweep: P is fitted with the pairs received.
    const FeedStep ended = endSweep();
    FeedStep step = ended.should_finish ? ended : addRotation(stamp, angle, rate, sequence);
    step.sweep_given_up = true;
    return step;
  }
  return addRotation(stamp, angle, rate, sequence);
}

FeedStep CalibrationFeed::addPrecessionState(Nanoseconds stamp, double angle, double rate, std::uint64_t sequence) {
  if (!session_ || !virtual_rotation_) return {};
  return addRotation(stamp, angle, rate, sequence);
}

FeedStep CalibrationFeed::addRotation(Nanoseconds stamp, double angle, double rate, std::uint64_t sequence) {
  FeedStep step;
  // The rule ended the run on an earlier record, and the waves are on their way to it: the records
  // after it are not the run's, so that it holds the same samples however far the waves trail.
  if (watch_finish_ && finish_pending_) return step;
  const std::uint64_t restarts = session_->counters().restarts;
  const bool taken = session_->addRotationRecord(stamp, angle, rate, sequence);
  noteRestart(restarts, &step);
  if (!watch_finish_ || !taken) return step;
  last_rotation_ = stamp;
  waves_reached_rotation_ = last_taken_wave_ >= stamp;
  if (!session_->shouldFinish()) return step;
  if (waves_reached_rotation_) {
    step.should_finish = true;
  } else {
    finish_pending_ = true;  // finished by the wave that reaches this record
  }
  return step;
}

FeedStep CalibrationFeed::addReference(Nanoseconds stamp, const WaveParameters& wave) {
  if (!session_ || !pairs_) return {};
  pairing_.addReference(stamp, wave);
  return {};
}

FeedStep CalibrationFeed::addSweepEnd(Nanoseconds stamp) {
  if (!session_ || !pairs_) return {};
  // Every generator reference has arrived. The raw channels that pair with them may still be queued on
  // their own connection (a live run once lost the last 87 of 1440 pairs that way, which biased P):
  // the sweep ends once the channels reach this stamp.
  if (sweep_end_ == 0 && (pairing_.waitingReferences() > 0 || session_->counters().used > 0)) {
    sweep_end_ = stamp;
    if (last_channels_ >= sweep_end_) return endSweep();
  }
  return {};
}

FeedStep CalibrationFeed::endSweep() {
  FeedStep step;
  sweep_end_ = 0;
  session_->generatorSweepEnded();
  step.should_finish = watch_finish_ && session_->shouldFinish();
  return step;
}

}  // namespace core
}  // namespace hrg_gyro
