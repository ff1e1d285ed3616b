#include "hrg_gyro/core/processing/bias_capture.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "hrg_gyro/core/common/yaml_field.h"
#include "hrg_gyro/core/processing/gyro_processor.h"

namespace hrg_gyro {
namespace core {
namespace {

std::string format(const char* pattern, double a, double b = 0.0, double c = 0.0) {
  char buffer[256];
  std::snprintf(buffer, sizeof buffer, pattern, a, b, c);
  return buffer;
}

// The settings checked before any member is built on them (the stillness test's block).
const BiasCaptureSettings& validated(const BiasCaptureSettings& settings) {
  settings.validate();
  return settings;
}

}  // namespace

void BiasCaptureSettings::validate() const {
  if (!(duration > 0.0) || !std::isfinite(duration)) throw ConfigError("bias_capture/duration", "must be positive (s)");
  if (!(block > 0.0) || !(block <= duration)) {
    throw ConfigError("bias_capture/block", "must be positive and at most bias_capture/duration (s)");
  }
  if (!(max_motion > 0.0) || !std::isfinite(max_motion))
    throw ConfigError("bias_capture/max_motion", "must be positive (rad/s)");
  if (!(max_bias > 0.0) || !std::isfinite(max_bias))
    throw ConfigError("bias_capture/max_bias", "must be positive (rad/s)");
}

BiasCapture::BiasCapture(const BiasCaptureSettings& settings, const GyroParameters& in_force)
    : settings_(validated(settings)),
      in_force_(in_force),
      earth_rate_(in_force.earth_rate.verticalRate()),
      stillness_(1, settings.block) {}

void BiasCapture::abort(const std::string& reason) {
  if (finished_) return;
  refusal_ = reason;
  finished_ = true;
}

bool BiasCapture::add(const AngleIncrement& increment, std::uint8_t flags) {
  if (finished_) return true;
  if (flags & (kFlagGap | kFlagReset)) {
    abort(flags & kFlagReset ? "time went backwards during the capture" : "gap in the input during the capture");
    return true;
  }
  if (flags & kFlagPrecessing) {
    // The wave turned on command: its rate is not the still gyro's.
    abort("the wave was turned on command (precession loop) during the capture");
    return true;
  }
  const double dt = increment.dt;
  if (!(dt > 0.0)) return false;
  sum_dt_ += dt;
  sum_dtheta_ += increment.dtheta;
  sum_k_dt_ += increment.scale_factor * dt;
  sum_harmonic_d_dt_ += (increment.drift - in_force_.drift.meanAt(increment.frequency)) * dt;
  sum_dalpha_ += increment.dalpha;
  if (std::isfinite(increment.frequency)) {
    sum_frequency_dt_ += increment.frequency * dt;
    frequency_dt_ += dt;
  }
  ++samples_;
  stillness_.add(dt, &increment.dalpha);
  // Motion is judged as it happens, so a capture during motion ends without waiting.
  if (stillness_.moved(settings_.max_motion)) {
    abort(format("the gyro moved during the capture: block mean rates spread over %.3g rad/s (limit %.3g)",
                 2.0 * stillness_.worstHalfSpread(), 2.0 * settings_.max_motion));
    return true;
  }
  if (sum_dt_ >= settings_.duration) {
    stillness_.closePartialBlock(0.5);
    finished_ = true;
  }
  return finished_;
}

BiasCaptureResult BiasCapture::result() const {
  BiasCaptureResult r;
  r.seconds = sum_dt_;
  r.samples = samples_;
  r.earth_rate = earth_rate_;
  r.mean_rate = sum_dt_ > 0.0 ? sum_dalpha_ / sum_dt_ : 0.0;
  const double frequency = frequency_dt_ > 0.0 ? sum_frequency_dt_ / frequency_dt_ : NAN;
  r.previous_d0 = in_force_.drift.meanAt(frequency);
  if (stillness_.hasBlock()) {
    r.worst_motion = std::max(stillness_.highestMean(0) - r.mean_rate, r.mean_rate - stillness_.lowestMean(0));
  }
  if (!finished_) {
    r.reason = "the capture has not ended";
    return r;
  }
  if (!refusal_.empty()) {
    r.reason = refusal_;
    return r;
  }
  if (r.worst_motion > settings_.max_motion) {
    r.reason = format("the gyro moved during the capture: a block mean rate left the mean by %.3g rad/s (limit %.3g)",
                      r.worst_motion, settings_.max_motion);
    return r;
  }
  if (std::abs(r.mean_rate - earth_rate_) > settings_.max_bias) {
    r.reason = format("mean rate %.6g rad/s is %.3g rad/s from the Earth rate (limit %.3g): the gyro is turning",
                      r.mean_rate, r.mean_rate - earth_rate_, settings_.max_bias);
    return r;
  }
  r.new_d0 = (sum_dtheta_ - earth_rate_ * sum_k_dt_ - sum_harmonic_d_dt_) / sum_dt_;
  if (!std::isfinite(r.new_d0)) {
    r.reason = "the captured drift is not finite";
    return r;
  }
  const HarmonicModel& d = in_force_.drift;
  Eigen::MatrixXd values = d.nodeValues();
  values.row(0).array() += r.new_d0 - r.previous_d0;
  r.parameters = in_force_;
  r.parameters.drift = HarmonicModel(d.orders(), d.interpolator(), values);
  r.accepted = true;
  r.reason = format("D0 %.9g -> %.9g rad/s from %.1f s at rest", r.previous_d0, r.new_d0, r.seconds);
  return r;
}

std::string notesAfterBiasCapture(const std::string& notes, const std::string& when) {
  static const std::string kPrefix = "D0 from a turn-on bias capture at ";
  static const std::string kSeparator = "; ";
  std::string kept;
  for (std::size_t begin = 0; begin <= notes.size();) {
    std::size_t end = notes.find(kSeparator, begin);
    if (end == std::string::npos) end = notes.size();
    const std::string part = notes.substr(begin, end - begin);
    if (!part.empty() && part.compare(0, kPrefix.size(), kPrefix) != 0) {
      kept += (kept.empty() ? "" : kSeparator) + part;
    }
    begin = end + kSeparator.size();
  }
  return kPrefix + when + (kept.empty() ? "" : kSeparator + kept);
}

}  // namespace core
}  // namespace hrg_gyro
