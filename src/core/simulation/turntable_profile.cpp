#include "hrg_gyro/core/simulation/turntable_profile.h"

#include <algorithm>
#include <cmath>

#include "hrg_gyro/core/common/units.h"

namespace hrg_gyro {
namespace core {

namespace {

/// The Thue-Morse sequence: 0 1 1 0 1 0 0 1 ..., the parity of the number of ones in n. Its first 2^m
/// terms split 0..2^m - 1 into two sets with equal sums of every power below m.
int thueMorse(long n) {
  int parity = 0;
  for (unsigned long v = static_cast<unsigned long>(n); v != 0; v &= v - 1) parity ^= 1;
  return parity;
}

}  // namespace

void TurntableProfile::append(double duration, double rate0, double accel, const std::string& label) {
  if (duration <= 0.0) return;
  Piece p;
  if (!pieces_.empty()) {
    const Piece& last = pieces_.back();
    p.start = last.start + last.duration;
    p.angle0 = last.angle0 + last.rate0 * last.duration + 0.5 * last.accel * last.duration * last.duration;
  }
  p.duration = duration;
  p.rate0 = rate0;
  p.accel = accel;
  p.label = label;
  pieces_.push_back(p);
  if (ripple_fraction_ != 0.0) updateRippleOrigins();
}

void TurntableProfile::setRipple(double fraction, double frequency, double phase) {
  ripple_fraction_ = fraction;
  ripple_frequency_ = frequency;
  ripple_phase_ = phase;
  updateRippleOrigins();
}

double TurntableProfile::rippleIntegral(const Piece& p, double tau) const {
  // With u = w (start + s) + phi: the integral of (r0 + a s) sin(u) ds is
  // -(r0 + a s) cos(u) / w + a sin(u) / w^2.
  const double w = kTwoPi * ripple_frequency_;
  auto primitive = [&](double s) {
    const double u = w * (p.start + s) + ripple_phase_;
    return -(p.rate0 + p.accel * s) * std::cos(u) / w + p.accel * std::sin(u) / (w * w);
  };
  return primitive(tau) - primitive(0.0);
}

void TurntableProfile::updateRippleOrigins() {
  double sum = 0.0;
  for (Piece& p : pieces_) {
    p.ripple0 = sum;
    if (ripple_fraction_ != 0.0) sum += rippleIntegral(p, p.duration);
  }
}

double TurntableProfile::finalRate() const {
  if (pieces_.empty()) return 0.0;
  const Piece& last = pieces_.back();
  return last.rate0 + last.accel * last.duration;
}

void TurntableProfile::rampTo(double target, double acceleration, const std::string& label) {
  const double from = finalRate();
  if (from == target) return;
  const double a = std::copysign(acceleration, target - from);
  append((target - from) / a, from, a, label + "/ramp");
}

void TurntableProfile::moveBy(double angle, double cruise, double acceleration, const std::string& label) {
  // Trapezoidal (or triangular when the move is too short to reach the cruise rate) from rest to rest.
  const double dir = angle >= 0.0 ? 1.0 : -1.0;
  const double dist = std::abs(angle);
  double peak = std::abs(cruise);
  double t_acc = peak / acceleration;
  double d_acc = 0.5 * acceleration * t_acc * t_acc;
  if (2.0 * d_acc > dist) {
    peak = std::sqrt(dist * acceleration);
    t_acc = peak / acceleration;
    d_acc = 0.5 * dist;
  }
  const double t_cruise = (dist - 2.0 * d_acc) / peak;
  append(t_acc, 0.0, dir * acceleration, label + "/move");
  append(t_cruise, dir * peak, 0.0, label + "/move");
  append(t_acc, dir * peak, -dir * acceleration, label + "/move");
}

namespace {

/// A dual-rate segment's keys: the two plateau rates, how often the pair repeats and in which order.
struct DualRateSegment {
  std::vector<double> rates;
  long repeat = 1;
  bool balanced = false;  ///< Thue-Morse order (cancels a bias trend), else alternating
  double duration = 0.0, settle = 0.0;
};

DualRateSegment readDualRate(const YamlField& seg) {
  seg.rejectUnknownKeys({"type", "label", "rates", "duration", "settle", "repeat", "order"});
  DualRateSegment d;
  d.rates = seg["rates"].asDoubles(2);
  if (d.rates[0] == d.rates[1]) seg["rates"].fail("the two plateau rates must differ");
  d.repeat = seg.getInteger("repeat", 1);
  if (d.repeat < 1) seg["repeat"].fail("must be >= 1");
  const std::string order = seg.getString("order", "alternating");
  if (order != "alternating" && order != "balanced") {
    seg["order"].fail("must be 'alternating' or 'balanced', not '" + order + "'");
  }
  d.balanced = order == "balanced";
  d.duration = seg["duration"].asDouble();
  if (!(d.duration > 0.0)) seg["duration"].fail("must be positive");
  d.settle = seg.getDouble("settle", 0.0);
  return d;
}

/// A piecewise segment's [time, rate] points, from time 0, times strictly increasing.
void readPoints(const YamlField& seg, std::vector<double>* t, std::vector<double>* w) {
  seg.rejectUnknownKeys({"type", "label", "points"});
  const YamlField pts = seg["points"];
  pts.requireSequence();
  if (pts.size() < 2) pts.fail("need at least two [time, rate] points");
  t->resize(pts.size());
  w->resize(pts.size());
  for (std::size_t k = 0; k < pts.size(); ++k) {
    const std::vector<double> p = pts.at(k).asDoubles(2);
    (*t)[k] = p[0];
    (*w)[k] = p[1];
    if (k == 0 && p[0] != 0.0) pts.at(0).fail("the first point must be at time 0");
    if (k > 0 && !((*t)[k] > (*t)[k - 1])) pts.at(k).fail("times must be strictly increasing");
  }
}

}  // namespace

TurntableProfile TurntableProfile::parse(const YamlField& profile, double acceleration) {
  if (!(acceleration > 0.0)) throw ConfigError("turntable.acceleration", "must be positive (rad/s^2)");
  profile.requireSequence();
  if (profile.size() == 0) profile.fail("the profile needs at least one segment");
  TurntableProfile tp;
  for (std::size_t i = 0; i < profile.size(); ++i) {
    const YamlField seg = profile.at(i);
    seg.requireMap();
    const std::string type = seg["type"].asString();
    const std::string label = seg.getString("label", type + "_" + std::to_string(i));
    auto positive = [&](const char* key) {
      const double v = seg[key].asDouble();
      if (!(v > 0.0)) seg[key].fail("must be positive");
      return v;
    };
    if (type == "dwell") {
      seg.rejectUnknownKeys({"type", "label", "duration"});
      tp.rampTo(0.0, acceleration, label);
      tp.append(positive("duration"), 0.0, 0.0, label);
    } else if (type == "rate") {
      seg.rejectUnknownKeys({"type", "label", "rate", "duration", "settle"});
      const double rate = seg["rate"].asDouble();
      tp.rampTo(rate, acceleration, label);
      tp.append(seg.getDouble("settle", 0.0), rate, 0.0, label + "/settle");
      tp.append(positive("duration"), rate, 0.0, label);
    } else if (type == "dual_rate") {
      const DualRateSegment d = readDualRate(seg);
      const std::vector<double>& rates = d.rates;
      const double duration = d.duration, settle = d.settle;
      const double reversal = std::abs(rates[1] - rates[0]) / acceleration;  // s
      for (long n = 0; n < 2 * d.repeat; ++n) {
        const int k = d.balanced ? thueMorse(n) : static_cast<int>(n % 2);
        const std::string sub = label + "/rate" + std::to_string(k + 1);
        if (n > 0 && tp.finalRate() == rates[k]) {
          // The same rate again: hold it for as long as a reversal takes, so the plateaus stay
          // evenly spaced and the balanced order cancels a bias trend exactly.
          tp.append(reversal + settle, rates[k], 0.0, sub + "/settle");
        } else {
          tp.rampTo(rates[k], acceleration, sub);
          tp.append(settle, rates[k], 0.0, sub + "/settle");
        }
        tp.append(duration, rates[k], 0.0, sub);
      }
    } else if (type == "steps") {
      seg.rejectUnknownKeys({"type", "label", "angle", "rate", "dwell", "count"});
      const double angle = seg["angle"].asDouble();
      if (angle == 0.0) seg["angle"].fail("must be non-zero");
      const double cruise = positive("rate"), dwell = positive("dwell");
      const long count = seg["count"].asInteger();
      if (count < 1) seg["count"].fail("must be >= 1");
      tp.rampTo(0.0, acceleration, label);
      tp.append(dwell, 0.0, 0.0, label + "/dwell");
      for (long k = 0; k < count; ++k) {
        tp.moveBy(angle, cruise, acceleration, label);
        tp.append(dwell, 0.0, 0.0, label + "/dwell");
      }
    } else if (type == "piecewise") {
      std::vector<double> t, w;
      readPoints(seg, &t, &w);
      tp.rampTo(w[0], acceleration, label);
      for (std::size_t k = 1; k < t.size(); ++k) {
        const double dt = t[k] - t[k - 1];
        tp.append(dt, w[k - 1], (w[k] - w[k - 1]) / dt, label);
      }
    } else {
      seg["type"].fail("unknown segment type '" + type + "' (dwell, rate, dual_rate, steps, piecewise)");
    }
  }
  tp.rampTo(0.0, acceleration, "end");
  return tp;
}

const TurntableProfile::Piece& TurntableProfile::pieceAt(double t) const {
  if (cursor_ >= pieces_.size()) cursor_ = 0;
  if (t < pieces_[cursor_].start) cursor_ = 0;
  while (cursor_ + 1 < pieces_.size() && t >= pieces_[cursor_ + 1].start) ++cursor_;
  return pieces_[cursor_];
}

void TurntableProfile::evaluate(double t, double* angle, double* rate, const std::string** label) const {
  static const std::string kNone = "none";
  if (pieces_.empty()) {
    *angle = 0.0;
    *rate = 0.0;
    if (label) *label = &kNone;
    return;
  }
  const Piece& p = pieceAt(t);
  const double tau = std::clamp(t - p.start, 0.0, p.duration);
  *angle = p.angle0 + p.rate0 * tau + 0.5 * p.accel * tau * tau;
  *rate = p.rate0 + p.accel * tau;
  if (t > p.start + p.duration) *angle += *rate * (t - p.start - p.duration);  // hold after the end
  if (ripple_fraction_ != 0.0) {
    // The ripple stops where the profile ends (its last piece comes to rest when parsed).
    *angle += ripple_fraction_ * (p.ripple0 + rippleIntegral(p, tau));
    if (t <= p.start + p.duration) {
      *rate *= 1.0 + ripple_fraction_ * std::sin(kTwoPi * ripple_frequency_ * (p.start + tau) + ripple_phase_);
    }
  }
  if (label) *label = &p.label;
}

}  // namespace core
}  // namespace hrg_gyro
