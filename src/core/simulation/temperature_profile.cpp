#include "hrg_gyro/core/simulation/temperature_profile.h"

#include <algorithm>
#include <cmath>

#include "hrg_gyro/core/common/number_format.h"

namespace hrg_gyro {
namespace core {
namespace {

/// Plausible temperatures of a resonator in a test chamber, degC.
constexpr double kMinTemperature = -100.0;
constexpr double kMaxTemperature = 200.0;

}  // namespace

double TemperatureProfile::finalTemperature() const {
  if (pieces_.empty()) return start_temperature_;
  const Piece& p = pieces_.back();
  return valueIn(p, p.duration);
}

void TemperatureProfile::appendRamp(double duration, double to) {
  if (!(duration > 0.0)) return;
  Piece p;
  p.start = this->duration();
  p.duration = duration;
  p.from = finalTemperature();
  p.to = to;
  pieces_.push_back(p);
}

void TemperatureProfile::appendStep(double duration, double to, double time_constant) {
  if (!(duration > 0.0)) return;
  Piece p;
  p.start = this->duration();
  p.duration = duration;
  p.from = time_constant > 0.0 ? finalTemperature() : to;
  p.to = to;
  p.time_constant = std::max(0.0, time_constant);
  pieces_.push_back(p);
}

double TemperatureProfile::valueIn(const Piece& p, double dt) {
  dt = std::clamp(dt, 0.0, p.duration);
  if (p.time_constant > 0.0) return p.to + (p.from - p.to) * std::exp(-dt / p.time_constant);
  return p.from + (p.to - p.from) * (dt / p.duration);
}

double TemperatureProfile::evaluate(double t) const {
  if (pieces_.empty() || t < 0.0) return start_temperature_;
  if (cursor_ >= pieces_.size() || t < pieces_[cursor_].start) cursor_ = 0;
  while (cursor_ + 1 < pieces_.size() && t >= pieces_[cursor_ + 1].start) ++cursor_;
  const Piece& p = pieces_[cursor_];
  return valueIn(p, t - p.start);
}

double TemperatureProfile::minimum() const {
  double m = start_temperature_;
  for (const Piece& p : pieces_) m = std::min({m, p.from, valueIn(p, p.duration)});
  return m;
}

double TemperatureProfile::maximum() const {
  double m = start_temperature_;
  for (const Piece& p : pieces_) m = std::max({m, p.from, valueIn(p, p.duration)});
  return m;
}

TemperatureProfile TemperatureProfile::parse(const YamlField& profile, double start_temperature) {
  TemperatureProfile tp(start_temperature);
  profile.requireSequence();
  if (profile.size() == 0) profile.fail("the temperature profile needs at least one segment");
  auto temperature = [](const YamlField& seg, const char* key) {
    const double v = seg[key].asDouble();
    if (v < kMinTemperature || v > kMaxTemperature) {
      seg[key].fail("temperature must be in [-100, 200] degC, got " + formatDouble(v));
    }
    return v;
  };
  for (std::size_t i = 0; i < profile.size(); ++i) {
    const YamlField seg = profile.at(i);
    seg.requireMap();
    const std::string type = seg["type"].asString();
    auto positive = [&](const char* key) {
      const double v = seg[key].asDouble();
      if (!(v > 0.0)) seg[key].fail("must be positive (s)");
      return v;
    };
    if (type == "hold") {
      seg.rejectUnknownKeys({"type", "label", "duration"});
      tp.appendRamp(positive("duration"), tp.finalTemperature());
    } else if (type == "ramp") {
      seg.rejectUnknownKeys({"type", "label", "to", "duration", "rate"});
      const double to = temperature(seg, "to");
      const double change = std::abs(to - tp.finalTemperature());
      if (seg.has("duration") == seg.has("rate")) seg.fail("give exactly one of duration (s) and rate (degC/s)");
      double duration;
      if (seg.has("rate")) {
        const double rate = seg["rate"].asDouble();
        if (!(rate > 0.0)) seg["rate"].fail("must be positive (degC/s; the sign follows from `to`)");
        if (change == 0.0) seg["to"].fail("the ramp starts at this temperature already: use a hold");
        duration = change / rate;
      } else {
        duration = positive("duration");
      }
      tp.appendRamp(duration, to);
    } else if (type == "step") {
      seg.rejectUnknownKeys({"type", "label", "to", "duration", "time_constant"});
      const double to = temperature(seg, "to");
      const double tau = seg.getDouble("time_constant", 0.0);
      if (tau < 0.0) seg["time_constant"].fail("must be >= 0 (s)");
      tp.appendStep(positive("duration"), to, tau);
    } else {
      seg["type"].fail("unknown segment type '" + type + "' (hold, ramp, step)");
    }
  }
  return tp;
}

}  // namespace core
}  // namespace hrg_gyro
