#include "hrg_gyro/core/simulation/base_motion.h"

#include <Eigen/Geometry>
#include <cmath>
#include <string>

#include "hrg_gyro/core/common/units.h"
#include "hrg_gyro/core/simulation/gaussian_noise.h"

namespace hrg_gyro {
namespace core {
namespace {

constexpr double kKnockStep = 0.05;  // s: the knock's step

// The raised cosine 0.5 - 0.5 cos(pi u) from `start` over `duration`, and its rate.
void raisedCosine(double t, double start, double duration, double* value, double* rate) {
  const double u = (t - start) / duration;
  if (u <= 0.0) {
    *value = *rate = 0.0;
  } else if (u >= 1.0) {
    *value = 1.0;
    *rate = 0.0;
  } else {
    *value = 0.5 - 0.5 * std::cos(kPi * u);
    *rate = 0.5 * kPi / duration * std::sin(kPi * u);
  }
}

Eigen::Vector3d readVector(const YamlField& f) {
  const std::vector<double> v = f.asDoubles(3);
  return Eigen::Vector3d(v[0], v[1], v[2]);
}

void checkBand(const BaseBand& b, const std::string& key) {
  if (!(b.rms >= 0.0)) throw ConfigError(key + ".rms", "must be >= 0");
  if (!(b.low > 0.0) || !(b.high >= b.low) || b.high > 1e4)
    throw ConfigError(key + ".low", "need 0 < low <= high <= 1e4 Hz");
  if (b.components < 1 || b.components > 1000) throw ConfigError(key + ".components", "must be in [1, 1000]");
}

BaseBand readBand(const YamlField& f, const BaseBand& defaults) {
  f.requireMap().rejectUnknownKeys({"rms", "low", "high", "components"});
  BaseBand b = defaults;
  b.rms = f.getDouble("rms", b.rms);
  b.low = f.getDouble("low", b.low);
  b.high = f.getDouble("high", b.high);
  b.components = static_cast<int>(f.getInteger("components", b.components));
  return b;
}

}  // namespace

bool BaseMotionConfig::enabled() const {
  return !leans.empty() || !knocks.empty() || !sways.empty() || yaw_jitter.rms > 0.0 || vibration.rms > 0.0;
}

void BaseMotionConfig::validate(const std::string& prefix) const {
  for (std::size_t i = 0; i < leans.size(); ++i) {
    const std::string key = prefix + ".leans[" + std::to_string(i) + "]";
    if (!(leans[i].time >= 0.0)) throw ConfigError(key + ".time", "must be >= 0 s");
    if (!(leans[i].duration > 0.0) || leans[i].duration > 1e5)
      throw ConfigError(key + ".duration", "must be in (0, 1e5] s");
    if (!leans[i].rotation.allFinite() || leans[i].rotation.norm() > 0.1)
      throw ConfigError(key + ".rotation", "must be finite, at most 0.1 rad: a lean of the base, not a move");
  }
  for (std::size_t i = 0; i < knocks.size(); ++i) {
    const std::string key = prefix + ".knocks[" + std::to_string(i) + "]";
    const BaseKnock& k = knocks[i];
    if (!(k.time >= 0.0)) throw ConfigError(key + ".time", "must be >= 0 s");
    if (!k.rotation.allFinite() || k.rotation.norm() > 0.1)
      throw ConfigError(key + ".rotation", "must be finite, at most 0.1 rad");
    if (!(k.ring >= 0.0) || k.ring > 100.0) throw ConfigError(key + ".ring", "must be in [0, 100]");
    if (!(k.ring_frequency > 0.0) || k.ring_frequency > 1e4)
      throw ConfigError(key + ".ring_frequency", "must be in (0, 1e4] Hz");
    if (!(k.ring_decay > 0.0) || k.ring_decay > 100.0) throw ConfigError(key + ".ring_decay", "must be in (0, 100] s");
  }
  for (std::size_t i = 0; i < sways.size(); ++i) {
    const std::string key = prefix + ".sways[" + std::to_string(i) + "]";
    const BaseSway& s = sways[i];
    if (!(s.amplitude >= 0.0) || s.amplitude > 0.1) throw ConfigError(key + ".amplitude", "must be in [0, 0.1] rad");
    if (!(s.period > 0.0) || s.period > 1e5) throw ConfigError(key + ".period", "must be in (0, 1e5] s");
    if (!s.axis.allFinite() || std::abs(s.axis.norm() - 1.0) > 1e-6)
      throw ConfigError(key + ".axis", "must be a unit vector");
    if (!std::isfinite(s.phase)) throw ConfigError(key + ".phase", "must be finite");
  }
  checkBand(yaw_jitter, prefix + ".yaw_jitter");
  if (yaw_jitter.rms > 0.1) throw ConfigError(prefix + ".yaw_jitter.rms", "must be at most 0.1 rad");
  checkBand(vibration, prefix + ".vibration");
  if (vibration.rms > 100.0) throw ConfigError(prefix + ".vibration.rms", "must be at most 100 m/s^2");
}

BaseMotionConfig parseBaseMotion(const YamlField& section) {
  section.requireMap().rejectUnknownKeys({"leans", "knocks", "sways", "yaw_jitter", "vibration"});
  BaseMotionConfig c;
  if (section.has("leans")) {
    const YamlField list = section["leans"].requireSequence();
    for (std::size_t i = 0; i < list.size(); ++i) {
      const YamlField f = list.at(i).requireMap();
      f.rejectUnknownKeys({"time", "duration", "rotation"});
      BaseLean l;
      l.time = f["time"].asDouble();
      l.duration = f.getDouble("duration", l.duration);
      l.rotation = readVector(f["rotation"]);
      c.leans.push_back(l);
    }
  }
  if (section.has("knocks")) {
    const YamlField list = section["knocks"].requireSequence();
    for (std::size_t i = 0; i < list.size(); ++i) {
      const YamlField f = list.at(i).requireMap();
      f.rejectUnknownKeys({"time", "rotation", "ring", "ring_frequency", "ring_decay"});
      BaseKnock k;
      k.time = f["time"].asDouble();
      k.rotation = readVector(f["rotation"]);
      k.ring = f.getDouble("ring", k.ring);
      k.ring_frequency = f.getDouble("ring_frequency", k.ring_frequency);
      k.ring_decay = f.getDouble("ring_decay", k.ring_decay);
      c.knocks.push_back(k);
    }
  }
  if (section.has("sways")) {
    const YamlField list = section["sways"].requireSequence();
    for (std::size_t i = 0; i < list.size(); ++i) {
      const YamlField f = list.at(i).requireMap();
      f.rejectUnknownKeys({"amplitude", "period", "axis", "phase"});
      BaseSway s;
      s.amplitude = f["amplitude"].asDouble();
      s.period = f["period"].asDouble();
      if (f.has("axis")) s.axis = readVector(f["axis"]);
      s.phase = f.getDouble("phase", s.phase);
      c.sways.push_back(s);
    }
  }
  if (section.has("yaw_jitter")) c.yaw_jitter = readBand(section["yaw_jitter"], c.yaw_jitter);
  if (section.has("vibration")) c.vibration = readBand(section["vibration"], c.vibration);
  c.validate(section.path().empty() ? "base_motion" : section.path());
  return c;
}

BaseMotion::BaseMotion(const BaseMotionConfig& config, std::uint64_t seed) : config_(config) {
  config_.validate();
  enabled_ = config_.enabled();
  for (std::size_t i = 0; i < config_.leans.size(); ++i) {
    const Eigen::Vector3d& r = config_.leans[i].rotation;
    if (r.norm() > 0.0) parts_.push_back({r.normalized(), Part::kLean, i});
  }
  for (std::size_t i = 0; i < config_.knocks.size(); ++i) {
    const Eigen::Vector3d& r = config_.knocks[i].rotation;
    if (r.norm() > 0.0) parts_.push_back({r.normalized(), Part::kKnock, i});
  }
  for (std::size_t i = 0; i < config_.sways.size(); ++i) {
    // Made exactly unit (validate() lets 1e-6 through): off it, D is no rotation and w not its rate.
    parts_.push_back({config_.sways[i].axis.normalized(), Part::kSway, i});
  }
  // The random bands: their own stream of the scenario's seed, so that they do not shift other draws.
  GaussianNoise draws(seed ^ 0x6261736557616b65ull);
  auto band = [&draws](const BaseBand& b, std::vector<Sine>* out) {
    if (!(b.rms > 0.0)) return;
    const double amplitude = b.rms * std::sqrt(2.0 / b.components);
    for (int k = 0; k < b.components; ++k) {
      const double f = b.low + (b.high - b.low) * draws.uniform();
      out->push_back({amplitude, kTwoPi * f, kTwoPi * draws.uniform()});
    }
  };
  band(config_.yaw_jitter, &yaw_);
  if (!yaw_.empty()) parts_.push_back({Eigen::Vector3d::UnitZ(), Part::kYaw, 0});
  for (auto& axis : vibration_) band(config_.vibration, &axis);
}

void BaseMotion::angleOf(const Part& part, double t, double* angle, double* rate) const {
  switch (part.kind) {
    case Part::kLean: {
      const BaseLean& l = config_.leans[part.index];
      double s, ds;
      raisedCosine(t, l.time, l.duration, &s, &ds);
      *angle = l.rotation.norm() * s;
      *rate = l.rotation.norm() * ds;
      return;
    }
    case Part::kKnock: {
      const BaseKnock& k = config_.knocks[part.index];
      const double size = k.rotation.norm();
      double s, ds;
      raisedCosine(t, k.time, kKnockStep, &s, &ds);
      *angle = size * s;
      *rate = size * ds;
      const double tau = t - k.time;
      if (tau > 0.0) {
        const double w = kTwoPi * k.ring_frequency, e = std::exp(-tau / k.ring_decay), a = k.ring * size;
        *angle += a * e * std::sin(w * tau);
        *rate += a * e * (w * std::cos(w * tau) - std::sin(w * tau) / k.ring_decay);
      }
      return;
    }
    case Part::kSway: {
      const BaseSway& s = config_.sways[part.index];
      const double w = kTwoPi / s.period;
      *angle = s.amplitude * std::sin(w * t + s.phase);
      *rate = s.amplitude * w * std::cos(w * t + s.phase);
      return;
    }
    case Part::kYaw:
      *angle = *rate = 0.0;
      for (const Sine& s : yaw_) {
        *angle += s.amplitude * std::sin(s.omega * t + s.phase);
        *rate += s.amplitude * s.omega * std::cos(s.omega * t + s.phase);
      }
      return;
  }
}

void BaseMotion::stateAt(double t, Eigen::Matrix3d* rotation, Eigen::Vector3d* rate) const {
  // D = D_1 D_2 ... ; its spatial rate w = w_1 + D_1 w_2 + D_1 D_2 w_3 + ...
  Eigen::Matrix3d d = Eigen::Matrix3d::Identity();
  Eigen::Vector3d w = Eigen::Vector3d::Zero();
  for (const Part& p : parts_) {
    double angle, angle_rate;
    angleOf(p, t, &angle, &angle_rate);
    w += d * (p.axis * angle_rate);
    d = d * Eigen::AngleAxisd(angle, p.axis).toRotationMatrix();
  }
  *rotation = d;
  *rate = w;
}

Eigen::Matrix3d BaseMotion::rotationAt(double t) const {
  Eigen::Matrix3d d;
  Eigen::Vector3d w;
  stateAt(t, &d, &w);
  return d;
}

Eigen::Vector3d BaseMotion::accelerationAt(double t) const {
  Eigen::Vector3d a = Eigen::Vector3d::Zero();
  for (int i = 0; i < 3; ++i) {
    for (const Sine& s : vibration_[i]) a(i) += s.amplitude * std::sin(s.omega * t + s.phase);
  }
  return a;
}

Eigen::Vector3d BaseMotion::meanAccelerationOver(double a, double b) const {
  if (!(b > a)) return accelerationAt(a);
  Eigen::Vector3d v = Eigen::Vector3d::Zero();
  for (int i = 0; i < 3; ++i) {
    for (const Sine& s : vibration_[i]) {
      v(i) += s.amplitude * (std::cos(s.omega * a + s.phase) - std::cos(s.omega * b + s.phase)) / s.omega;
    }
  }
  return v / (b - a);
}

}  // namespace core
}  // namespace hrg_gyro
