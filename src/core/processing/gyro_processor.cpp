#include "hrg_gyro/core/processing/gyro_processor.h"

#include <cmath>
#include <string>

#include "hrg_gyro/core/common/number_format.h"
#include "hrg_gyro/core/common/yaml_field.h"

namespace hrg_gyro {
namespace core {

namespace {

double largestMean(const HarmonicModel& k) { return k.nodeValues().row(0).cwiseAbs().maxCoeff(); }

StampRule stampRule(const ProcessorConfig& c) {
  StampRule r;
  r.backward_reset = c.backward_reset;
  r.forward_jump = c.max_gap;  // a step beyond max_gap is a gap if it persists, a glitch if not
  r.persist = c.jump_persist;
  return r;
}

void requirePositive(const char* key, double value, const char* unit) {
  if (!(std::isfinite(value) && value > 0.0)) {
    throw ConfigError(key, std::string("must be a positive number of ") + unit + ", got " + formatDouble(value));
  }
}

}  // namespace

void validate(const ProcessorConfig& c) {
  requirePositive("max_gap", c.max_gap, "seconds");
  requirePositive("backward_reset", c.backward_reset, "seconds");
  if (c.jump_persist < 1 || c.jump_persist > 1000) {
    throw ConfigError("jump_persist", "must be in [1, 1000] samples, got " + std::to_string(c.jump_persist));
  }
  requirePositive("max_rate", c.max_rate, "rad/s");
  if (c.max_consecutive_jumps < 0) {
    throw ConfigError("max_consecutive_jumps", "must be >= 0, got " + std::to_string(c.max_consecutive_jumps));
  }
  const WaveLimits& l = c.limits;
  if (!(l.min_anisotropy > 0.0 && l.min_anisotropy < 1.0)) {
    throw ConfigError("min_anisotropy", "must be strictly between 0 and 1, got " + formatDouble(l.min_anisotropy));
  }
  if (!(std::isfinite(l.min_amplitude) && l.min_amplitude >= 0.0)) {
    throw ConfigError("min_amplitude", "must be a finite amplitude >= 0, got " + formatDouble(l.min_amplitude));
  }
  if (!(std::isfinite(l.max_amplitude) && l.max_amplitude > l.min_amplitude)) {
    throw ConfigError("max_amplitude", "must be finite and above min_amplitude (" + formatDouble(l.min_amplitude) +
                                           "), got " + formatDouble(l.max_amplitude));
  }
}

GyroProcessor::GyroProcessor(const ProcessorConfig& config, std::shared_ptr<const GyroParameters> parameters)
    : config_(config),
      timeline_(stampRule(config)),
      compensator_(std::move(parameters)),
      max_abs_k0_(largestMean(compensator_.parameters().scale_factor)) {}

void GyroProcessor::setParameters(std::shared_ptr<const GyroParameters> parameters) {
  const CorrectionMatrix old_p = compensator_.parameters().correction;
  compensator_ = Compensator(std::move(parameters));
  max_abs_k0_ = largestMean(compensator_.parameters().scale_factor);
  if (has_previous_ && !(compensator_.parameters().correction == old_p)) {
    WaveState w;
    if (estimateWave(compensator_.parameters().correction.apply(previous_z_), config_.limits, &w) == WaveStatus::kOk) {
      double half_turns;
      const double theta = unwrapper_.reanchor(w.theta, &half_turns);
      w.rebase(theta, half_turns);
      previous_cos_ = w.cos_theta;
      previous_sin_ = w.sin_theta;
    }
  }
}

void GyroProcessor::reset() {
  resetState();
  timeline_.clear();
}

void GyroProcessor::resetState() {
  unwrapper_.reset();
  has_previous_ = false;
  alpha_ = 0.0;
  consecutive_jumps_ = 0;
}

void GyroProcessor::countRejection(WaveStatus status) {
  switch (status) {
    case WaveStatus::kNonFinite:
      ++counters_.non_finite;
      break;
    case WaveStatus::kNoSignal:
      ++counters_.no_signal;
      break;
    case WaveStatus::kDegenerate:
      ++counters_.degenerate;
      break;
    case WaveStatus::kAmplitudeOutOfRange:
      ++counters_.amplitude_out_of_range;
      break;
    case WaveStatus::kOk:
      break;
  }
}

// The phases of process(), inline: process() is the per-sample hot path.

inline void GyroProcessor::reject(SampleVerdict verdict, ProcessorResult* r) {
  ++rejected_since_output_;
  *r = ProcessorResult();
  r->verdict = verdict;
}

inline bool GyroProcessor::admitStamp(Nanoseconds stamp, Nanoseconds* dt_ns, ProcessorResult* r) {
  switch (timeline_.check(stamp)) {
    case StampVerdict::kNext:
    case StampVerdict::kResumedAhead:  // a gap: admitStep flags it (dt > max_gap)
      break;
    case StampVerdict::kNewTimeline:
      ++counters_.resets;  // time went back for good (bag loop): start over
      resetState();
      pending_flags_ |= kFlagReset;
      return true;
    case StampVerdict::kNonPositive:
      ++counters_.zero_stamp;
      reject(SampleVerdict::kRejectedStamp, r);
      return false;
    case StampVerdict::kDuplicate:
      ++counters_.duplicate;
      reject(SampleVerdict::kDuplicate, r);
      return false;
    case StampVerdict::kBehind:
      ++counters_.out_of_order;
      reject(SampleVerdict::kOutOfOrder, r);
      return false;
    case StampVerdict::kJumpedBack:
    case StampVerdict::kJumpedAhead:
      ++counters_.stamp_jumps;
      reject(SampleVerdict::kStampJump, r);
      return false;
  }
  // The timeline's last stamp may be a sample whose values were rejected since: the step is from
  // the last accepted one, which lies before it.
  if (has_previous_) *dt_ns = stamp - previous_stamp_;
  return true;
}

inline void GyroProcessor::remember(const ChannelSample& in, const WaveState& wave) {
  has_previous_ = true;
  previous_stamp_ = in.stamp;
  previous_frequency_ = in.frequency;
  previous_z_ = in.z;
  previous_cos_ = wave.cos_theta;
  previous_sin_ = wave.sin_theta;
  ++counters_.accepted;
}

inline void GyroProcessor::anchor(const ChannelSample& in, WaveState* wave, ProcessorResult* r) {
  double half_turns;
  const double theta = unwrapper_.peek(wave->theta, &half_turns);
  unwrapper_.accept(wave->theta, half_turns);
  wave->rebase(theta, half_turns);
  remember(in, *wave);
  const WaveState w = *wave;  // *wave may be r->wave, which the reset below clears
  *r = ProcessorResult();
  r->verdict = SampleVerdict::kFirst;
  r->has_wave = true;
  r->wave = w;
  r->alpha = alpha_;
}

inline bool GyroProcessor::admitStep(double dt, double step, std::uint8_t* flags, bool* integrate) {
  if (dt > config_.max_gap) {
    ++counters_.gaps;
    if (dt > counters_.largest_gap) counters_.largest_gap = dt;
    *flags |= kFlagGap;
    *integrate = false;
  } else {
    const double limit = max_abs_k0_ * config_.max_rate * dt;
    if (std::abs(step) > limit) {
      if (++consecutive_jumps_ <= config_.max_consecutive_jumps) {
        ++counters_.jumps;
        return false;
      }
      *flags |= kFlagGap;  // the jump persists: take the new angle as a re-anchor
      *integrate = false;
    }
  }
  consecutive_jumps_ = 0;
  return true;
}

inline std::uint8_t GyroProcessor::frequencyFlags(double f_mid) {
  const GyroParameters& p = compensator_.parameters();
  if (p.scale_factor.frequencyDependent() || p.drift.frequencyDependent()) {
    if (std::isnan(f_mid)) {
      ++counters_.frequency_unknown;
      return kFlagFrequencyUnknown;
    }
    if (!p.scale_factor.interpolator().inRange(f_mid) || !p.drift.interpolator().inRange(f_mid)) {
      ++counters_.frequency_out_of_range;
      return kFlagFrequencyOutOfRange;
    }
  }
  return 0;
}

inline AngleIncrement GyroProcessor::reanchorIncrement(double theta, double dt, double f_mid, const WaveState& wave) {
  AngleIncrement increment;
  increment.dt = dt;
  increment.theta_mid = theta;
  increment.frequency = f_mid;
  const AngleIncrement at =
      compensator_.step(theta, theta, 0.0, f_mid, wave.cos_theta, wave.sin_theta, wave.cos_theta, wave.sin_theta);
  increment.scale_factor = at.scale_factor;
  increment.drift = at.drift;
  return increment;
}

__attribute__((always_inline)) inline void GyroProcessor::advance(const ChannelSample& in, WaveStatus status,
                                                                  WaveState* wave_state, ProcessorResult* result,
                                                                  StepBatch* deferred) {
  // Every path sets every field of *result: rejections and the first sample start from a default
  // result, the accepted path (the hot one) writes each field itself.
  ProcessorResult& r = *result;
  ++counters_.received;
  Nanoseconds dt_ns = 0;
  if (!admitStamp(in.stamp, &dt_ns, &r)) return;

  WaveState& wave = *wave_state;
  if (status != WaveStatus::kOk) {
    countRejection(status);
    reject(SampleVerdict::kRejectedValue, &r);
    r.wave_status = status;
    return;
  }
  if (!has_previous_) {
    anchor(in, &wave, &r);
    return;
  }

  const double dt = toSeconds(dt_ns);
  const double previous_theta = unwrapper_.last();
  double half_turns;
  const double theta = unwrapper_.peek(wave.theta, &half_turns);
  std::uint8_t flags = pending_flags_;
  bool integrate = true;
  if (!admitStep(dt, theta - previous_theta, &flags, &integrate)) {
    reject(SampleVerdict::kRejectedJump, &r);
    return;
  }
  unwrapper_.accept(wave.theta, half_turns);
  wave.rebase(theta, half_turns);

  const double f_mid = 0.5 * (in.frequency + previous_frequency_);
  flags |= frequencyFlags(f_mid);
  if (integrate && deferred != nullptr) {
    // processBatch computes the increment and alpha after the block (r.alpha below is provisional).
    deferred->add(previous_theta, theta, dt, f_mid, previous_cos_, previous_sin_, wave.cos_theta, wave.sin_theta,
                  &r.increment);
  } else if (integrate) {
    r.increment = compensator_.step(previous_theta, theta, dt, f_mid, previous_cos_, previous_sin_, wave.cos_theta,
                                    wave.sin_theta);
    alpha_ += r.increment.dalpha;
  } else {
    r.increment = reanchorIncrement(theta, dt, f_mid, wave);
  }
  remember(in, wave);
  ++counters_.outputs;
  r.verdict = SampleVerdict::kAccepted;
  r.wave_status = WaveStatus::kOk;
  r.has_wave = true;
  if (&r.wave != &wave) r.wave = wave;
  r.has_output = true;
  r.alpha = alpha_;
  r.flags = flags;
  r.rejected_before = rejected_since_output_;
  rejected_since_output_ = 0;
  pending_flags_ = 0;
}

__attribute__((always_inline)) inline void GyroProcessor::processInto(const ChannelSample& in,
                                                                      ProcessorResult* result) {
  // The wave state is estimated straight into the result (a rejection resets it there).
  const WaveStatus status =
      estimateWave(compensator_.parameters().correction.apply(in.z), config_.limits, &result->wave);
  advance(in, status, &result->wave, result, nullptr);
}

ProcessorResult GyroProcessor::process(const ChannelSample& in) {
  ProcessorResult r;
  processInto(in, &r);
  return r;
}

void GyroProcessor::process(const ChannelSample& in, ProcessorResult* result) { processInto(in, result); }

void GyroProcessor::processBatch(const ChannelSample* in, std::size_t n, ProcessorResult* out) {
  // A block at a time, in passes that together apply exactly what process() applies sample by
  // sample:
  // 1. The wave states of (E - P) z, several samples per instruction (estimateWaves), straight into
  //    the results: they depend on the sample alone and on P, which cannot change inside a batch.
  // 2. The rules in order (stamps, unwrapping, gaps, jumps). Where the models allow increments
  //    four at a time (ModelPairEvaluator::lanesApply), each integrated step's inputs are queued
  //    instead, and
  // 3. the queued increments are computed (Compensator::steps), then alpha summed in order.
  constexpr std::size_t kBlock = StepBatch::kCapacity;
  WaveStatus statuses[kBlock];
  bool integrated[kBlock];
  StepBatch steps;
  StepBatch* const deferred = compensator_.stepsInLanes() ? &steps : nullptr;
  const CorrectionMatrix& correction = compensator_.parameters().correction;
  for (std::size_t start = 0; start < n; start += kBlock) {
    const std::size_t m = n - start < kBlock ? n - start : kBlock;
    ProcessorResult* block = out + start;
    estimateWaves(&in[start].z, sizeof(ChannelSample), correction, m, config_.limits, &block[0].wave,
                  sizeof(ProcessorResult), statuses);
    if (deferred == nullptr) {
      for (std::size_t j = 0; j < m; ++j) advance(in[start + j], statuses[j], &block[j].wave, &block[j], nullptr);
      continue;
    }
    const double alpha_before = alpha_;
    for (std::size_t j = 0; j < m; ++j) {
      const std::size_t queued = steps.size;
      advance(in[start + j], statuses[j], &block[j].wave, &block[j], &steps);
      integrated[j] = steps.size != queued;
    }
    compensator_.steps(&steps);
    // alpha as process() accumulates it: a first sample starts it at 0 (a first sample only
    // follows a start or reset(), which zero it), an integrated step adds its increment.
    double alpha = alpha_before;
    for (std::size_t j = 0; j < m; ++j) {
      ProcessorResult& r = block[j];
      if (r.verdict == SampleVerdict::kFirst) {
        alpha = 0.0;
      } else if (r.verdict != SampleVerdict::kAccepted) {
        continue;
      }
      if (integrated[j]) alpha += r.increment.dalpha;
      r.alpha = alpha;
    }
    // A reset with no first sample after it in this block: alpha waits at 0 for the next one.
    alpha_ = has_previous_ ? alpha : 0.0;
  }
}

}  // namespace core
}  // namespace hrg_gyro
