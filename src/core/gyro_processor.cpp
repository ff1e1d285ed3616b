#include "hrg_gyro/core/gyro_processor.h"

#include <cmath>
#include <string>

#include "hrg_gyro/core/yaml_field.h"

namespace hrg_gyro {
namespace core {

namespace {

double largestMean(const HarmonicModel& k) { return k.nodeValues().row(0).cwiseAbs().maxCoeff(); }

void requirePositive(const char* key, double value, const char* unit) {
  if (!(std::isfinite(value) && value > 0.0)) {
    throw ConfigError(key, std::string("must be a positive number of ") + unit + ", got " + formatDouble(value));
  }
}

}  // namespace

void validate(const ProcessorConfig& c) {
  requirePositive("max_gap", c.max_gap, "seconds");
  requirePositive("backward_reset", c.backward_reset, "seconds");
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
    : config_(config), compensator_(std::move(parameters)), max_abs_k0_(largestMean(compensator_.parameters().scale_factor)) {}

void GyroProcessor::setParameters(std::shared_ptr<const GyroParameters> parameters) {
  const CorrectionMatrix old_p = compensator_.parameters().correction;
  compensator_ = Compensator(std::move(parameters));
  max_abs_k0_ = largestMean(compensator_.parameters().scale_factor);
  if (has_previous_ && !(compensator_.parameters().correction == old_p)) {
    WaveState w;
    if (estimateWave(compensator_.parameters().correction.apply(previous_z_), config_.limits, &w) == WaveStatus::kOk) {
      ThetaUnwrapper rebased;
      rebased.unwrap(unwrapper_.last());
      const double theta = rebased.unwrap(w.theta);
      w.rebase(theta);
      unwrapper_ = ThetaUnwrapper();
      unwrapper_.unwrap(theta);
      previous_cos_ = w.cos_theta;
      previous_sin_ = w.sin_theta;
    }
  }
}

void GyroProcessor::reset() {
  unwrapper_.reset();
  has_previous_ = false;
  alpha_ = 0.0;
  consecutive_jumps_ = 0;
}

void GyroProcessor::countRejection(WaveStatus status) {
  switch (status) {
    case WaveStatus::kNonFinite: ++counters_.non_finite; break;
    case WaveStatus::kNoSignal: ++counters_.no_signal; break;
    case WaveStatus::kDegenerate: ++counters_.degenerate; break;
    case WaveStatus::kAmplitudeOutOfRange: ++counters_.amplitude_out_of_range; break;
    case WaveStatus::kOk: break;
  }
}

ProcessorResult GyroProcessor::process(const ChannelSample& in) {
  ProcessorResult r;
  ++counters_.received;
  if (in.stamp <= 0) {
    ++counters_.zero_stamp;
    ++rejected_since_output_;
    r.verdict = SampleVerdict::kRejectedStamp;
    return r;
  }
  Nanoseconds dt_ns = 0;
  if (has_previous_) {
    dt_ns = in.stamp - previous_stamp_;
    if (dt_ns == 0) {
      ++counters_.duplicate;
      ++rejected_since_output_;
      r.verdict = SampleVerdict::kDuplicate;
      return r;
    }
    if (dt_ns < 0) {
      if (toSeconds(-dt_ns) <= config_.backward_reset) {
        ++counters_.out_of_order;
        ++rejected_since_output_;
        r.verdict = SampleVerdict::kOutOfOrder;
        return r;
      }
      ++counters_.resets;  // time jumped back (bag loop): start over
      reset();
      pending_flags_ |= kFlagReset;
    }
  }

  WaveState wave;
  r.wave_status = estimateWave(compensator_.parameters().correction.apply(in.z), config_.limits, &wave);
  if (r.wave_status != WaveStatus::kOk) {
    countRejection(r.wave_status);
    ++rejected_since_output_;
    r.verdict = SampleVerdict::kRejectedValue;
    return r;
  }

  if (!has_previous_) {
    wave.rebase(unwrapper_.unwrap(wave.theta));
    has_previous_ = true;
    previous_stamp_ = in.stamp;
    previous_frequency_ = in.frequency;
    previous_z_ = in.z;
    previous_cos_ = wave.cos_theta;
    previous_sin_ = wave.sin_theta;
    ++counters_.accepted;
    r.verdict = SampleVerdict::kFirst;
    r.has_wave = true;
    r.wave = wave;
    r.alpha = alpha_;
    return r;
  }

  const double dt = toSeconds(dt_ns);
  const double previous_theta = unwrapper_.last();
  const double theta = wave.theta + kPi * std::round((previous_theta - wave.theta) / kPi);
  std::uint8_t flags = pending_flags_;
  bool integrate = true;
  if (dt > config_.max_gap) {
    ++counters_.gaps;
    if (dt > counters_.largest_gap) counters_.largest_gap = dt;
    flags |= kFlagGap;
    integrate = false;
  } else {
    const double limit = max_abs_k0_ * config_.max_rate * dt;
    if (std::abs(theta - previous_theta) > limit) {
      if (++consecutive_jumps_ <= config_.max_consecutive_jumps) {
        ++counters_.jumps;
        ++rejected_since_output_;
        r.verdict = SampleVerdict::kRejectedJump;
        return r;
      }
      flags |= kFlagGap;  // the jump persists: take the new angle as a re-anchor
      integrate = false;
    }
  }
  consecutive_jumps_ = 0;
  unwrapper_.unwrap(theta);
  wave.rebase(theta);

  const double f_mid = 0.5 * (in.frequency + previous_frequency_);
  const GyroParameters& p = compensator_.parameters();
  if (p.scale_factor.frequencyDependent() || p.drift.frequencyDependent()) {
    if (std::isnan(f_mid)) {
      flags |= kFlagFrequencyUnknown;
      ++counters_.frequency_unknown;
    } else if (!p.scale_factor.interpolator().inRange(f_mid) || !p.drift.interpolator().inRange(f_mid)) {
      flags |= kFlagFrequencyOutOfRange;
      ++counters_.frequency_out_of_range;
    }
  }
  if (integrate) {
    r.increment = compensator_.step(previous_theta, theta, dt, f_mid, previous_cos_, previous_sin_, wave.cos_theta,
                                    wave.sin_theta);
    alpha_ += r.increment.dalpha;
  } else {
    r.increment = AngleIncrement();
    r.increment.dt = dt;
    r.increment.theta_mid = theta;
    r.increment.frequency = f_mid;
    const AngleIncrement at =
        compensator_.step(theta, theta, 0.0, f_mid, wave.cos_theta, wave.sin_theta, wave.cos_theta, wave.sin_theta);
    r.increment.scale_factor = at.scale_factor;
    r.increment.drift = at.drift;
  }
  previous_stamp_ = in.stamp;
  previous_frequency_ = in.frequency;
  previous_z_ = in.z;
  previous_cos_ = wave.cos_theta;
  previous_sin_ = wave.sin_theta;
  ++counters_.accepted;
  ++counters_.outputs;
  r.verdict = SampleVerdict::kAccepted;
  r.has_wave = true;
  r.wave = wave;
  r.has_output = true;
  r.alpha = alpha_;
  r.flags = flags;
  r.rejected_before = rejected_since_output_;
  rejected_since_output_ = 0;
  pending_flags_ = 0;
  return r;
}

}  // namespace core
}  // namespace hrg_gyro
