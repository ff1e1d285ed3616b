#include "hrg_gyro/core/simulation/turntable_log.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

#include "hrg_gyro/core/common/number_format.h"

namespace hrg_gyro {
namespace core {

namespace {

/// Largest angle error of a rest: an indexer off by more than 0.1 rad is not at its position.
constexpr double kMaxRestAngleError = 0.1;  // rad

const char* const kGlitchKeys[kTurntableGlitchKinds] = {"nan_rate", "absurd_rate", "infinite_angle", "zero_stamp",
                                                        "backward_stamp"};

}  // namespace

double TableClockConfig::errorAt(double t) const {
  double error = offset + rate_error * t;
  for (const TableClockStep& step : steps) {
    if (step.at <= t) error += step.size;
  }
  return error;
}

TableClockConfig TableClockConfig::parse(const YamlField& clock) {
  clock.requireMap();
  clock.rejectUnknownKeys({"offset", "jitter", "rate_error", "steps"});
  TableClockConfig c;
  c.offset = clock.getDouble("offset", 0.0);
  if (!std::isfinite(c.offset)) clock["offset"].fail("must be finite (s, the controller's clock minus the gyro's)");
  c.jitter = clock.getDouble("jitter", 0.0);
  if (!(std::isfinite(c.jitter) && c.jitter >= 0.0)) clock["jitter"].fail("must be >= 0 (s, standard deviation)");
  c.rate_error = clock.getDouble("rate_error", 0.0);
  if (!(std::isfinite(c.rate_error) && std::abs(c.rate_error) < 1.0)) {
    clock["rate_error"].fail("must be in (-1, 1) (s per s; a real clock is off by parts per million)");
  }
  if (clock.has("steps")) {
    const YamlField steps = clock["steps"];
    steps.requireSequence();
    for (std::size_t i = 0; i < steps.size(); ++i) {
      const std::vector<double> step = steps.at(i).asDoubles(2);
      if (!(std::isfinite(step[0]) && step[0] >= 0.0)) steps.at(i).fail("the time must be >= 0 s (from the start)");
      if (!std::isfinite(step[1])) steps.at(i).fail("the size must be finite (s)");
      c.steps.push_back({step[0], step[1]});
    }
  }
  return c;
}

double TurntableGlitchRates::total() const { return std::accumulate(per_record.begin(), per_record.end(), 0.0); }

TurntableLogConfig TurntableLogConfig::parse(const YamlField& log) {
  log.requireMap();
  log.rejectUnknownKeys({"rate", "angle_noise", "angle_resolution", "logged_rate", "drop_probability", "gaps",
                         "stamp_glitches", "glitches", "clock", "rest_angle_errors", "rest_angle_error_std"});
  TurntableLogConfig c;
  c.rate = log.getDouble("rate", 0.0);
  if (!(std::isfinite(c.rate) && c.rate >= 0.0)) {
    log["rate"].fail("must be >= 0 Hz (0: one record with every output sample)");
  }
  c.angle_noise = log.getDouble("angle_noise", 0.0);
  if (!(std::isfinite(c.angle_noise) && c.angle_noise >= 0.0)) log["angle_noise"].fail("must be >= 0 (rad)");
  c.angle_resolution = log.getDouble("angle_resolution", 0.0);
  if (!(std::isfinite(c.angle_resolution) && c.angle_resolution >= 0.0)) {
    log["angle_resolution"].fail("must be >= 0 (rad per encoder count; 0: not quantised)");
  }
  const std::string rate_source = log.getString("logged_rate", "table");
  if (rate_source == "table") {
    c.logged_rate = LoggedRate::kTable;
  } else if (rate_source == "differenced_angle") {
    c.logged_rate = LoggedRate::kDifferencedAngle;
  } else {
    log["logged_rate"].fail("must be 'table' or 'differenced_angle', not '" + rate_source + "'");
  }
  c.delivery = DeliveryConfig::parse(log);
  if (log.has("glitches")) {
    const YamlField g = log["glitches"];
    g.requireMap();
    g.rejectUnknownKeys(std::vector<std::string>(std::begin(kGlitchKeys), std::end(kGlitchKeys)));
    for (int k = 0; k < kTurntableGlitchKinds; ++k) {
      const double p = g.getDouble(kGlitchKeys[k], 0.0);
      if (!(p >= 0.0 && p <= 1.0)) g[kGlitchKeys[k]].fail("must be a probability per record, in [0, 1]");
      c.glitches.per_record[k] = p;
    }
    if (!(c.glitches.total() <= 1.0)) g.fail("the glitch rates add up to more than 1 per record");
  }
  if (log.has("clock")) c.clock = TableClockConfig::parse(log["clock"]);
  if (log.has("rest_angle_errors")) {
    c.rest_errors.errors = log["rest_angle_errors"].asDoubles();
    for (std::size_t k = 0; k < c.rest_errors.errors.size(); ++k) {
      if (!(std::abs(c.rest_errors.errors[k]) <= kMaxRestAngleError)) {
        log["rest_angle_errors"].at(k).fail("must be at most " + formatDouble(kMaxRestAngleError) +
                                            " rad in magnitude (an indexer's position error)");
      }
    }
  }
  c.rest_errors.sigma = log.getDouble("rest_angle_error_std", 0.0);
  if (!(c.rest_errors.sigma >= 0.0 && c.rest_errors.sigma <= kMaxRestAngleError)) {
    log["rest_angle_error_std"].fail("must be in [0, " + formatDouble(kMaxRestAngleError) + "] rad");
  }
  return c;
}

TurntableLogger::TurntableLogger(const TurntableLogConfig& config, std::uint64_t seed)
    : config_(config),
      encoder_noise_(seed ^ 0x3c6ef372fe94f82bULL),
      glitch_draws_(seed ^ 0xa54ff53a5f1d36f1ULL),
      clock_jitter_(seed ^ 0xcbbb9d5dc1059ed8ULL),
      rest_draws_(seed ^ 0x1f83d9abfb41bd6bULL),
      delivery_(config.delivery, seed ^ 0x510e527fade682d1ULL) {}

void TurntableLogger::log(double t, Nanoseconds stamp, double angle, double rate,
                          std::vector<TurntableLogRecord>* out) {
  TurntableLogRecord r;
  r.index = counters_.logged;
  r.time = t;
  r.stamp = stamp;
  if (config_.clock.enabled()) {
    double error = config_.clock.errorAt(t);
    if (config_.clock.jitter > 0.0) error += config_.clock.jitter * clock_jitter_.next();
    // ROS time 0 means unset: a clock far behind still stamps after it.
    r.stamp = std::max<Nanoseconds>(1, stamp + toNanoseconds(error));
  }
  r.angle = angle;
  if (config_.rest_errors.enabled()) {
    if (rate == 0.0 && !at_rest_) {
      const double drawn = rest_draws_.next();
      const std::vector<double>& given = config_.rest_errors.errors;
      rest_error_ = rests_ < given.size() ? given[rests_] : config_.rest_errors.sigma * drawn;
      ++rests_;
    }
    at_rest_ = rate == 0.0;
    if (at_rest_) r.angle += rest_error_;
  }
  if (config_.angle_noise > 0.0) r.angle += config_.angle_noise * encoder_noise_.next();
  if (config_.angle_resolution > 0.0)
    r.angle = config_.angle_resolution * std::round(r.angle / config_.angle_resolution);
  r.rate = rate;
  if (config_.logged_rate == LoggedRate::kDifferencedAngle) {
    // The controller's own difference; its first record has none and reports the drive's rate.
    if (has_previous_ && t > previous_time_) r.rate = (r.angle - previous_angle_) / (t - previous_time_);
    has_previous_ = true;
    previous_time_ = t;
    previous_angle_ = r.angle;
  }
  ++counters_.logged;
  // Every record takes its draws whether or not it is delivered, so losses and glitches are independent.
  const double total = config_.glitches.total();
  if (total > 0.0) {
    double u = glitch_draws_.uniform();
    for (int k = 0; k < kTurntableGlitchKinds; ++k) {
      u -= config_.glitches.per_record[k];
      if (u < 0.0) {
        r.glitch = static_cast<TurntableGlitch>(k);
        break;
      }
    }
  }
  if (!delivery_.delivered(t)) {
    ++counters_.lost;
    return;
  }
  r.stamp += delivery_.stampOffset(t);
  switch (r.glitch) {
    case TurntableGlitch::kNanRate:
      r.rate = std::numeric_limits<double>::quiet_NaN();
      break;
    case TurntableGlitch::kAbsurdRate:
      r.rate = std::copysign(kAbsurdTableRate, rate == 0.0 ? 1.0 : rate);
      break;
    case TurntableGlitch::kInfiniteAngle:
      r.angle = std::numeric_limits<double>::infinity();
      break;
    case TurntableGlitch::kZeroStamp:
      r.stamp = 0;
      break;
    case TurntableGlitch::kBackwardStamp:
      r.stamp = std::max<Nanoseconds>(1, r.stamp - toNanoseconds(kBackwardStampJump));  // on the controller's clock
      break;
    case TurntableGlitch::kNone:
      break;
  }
  if (r.glitch != TurntableGlitch::kNone) ++counters_.glitches[static_cast<int>(r.glitch)];
  out->push_back(r);
}

}  // namespace core
}  // namespace hrg_gyro
