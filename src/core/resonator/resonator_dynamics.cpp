#include "hrg_gyro/core/resonator/resonator_dynamics.h"

#include <cmath>
#include <stdexcept>

#include "hrg_gyro/core/common/units.h"

namespace hrg_gyro {
namespace core {
namespace {

bool standing(const WaveParameters& w) {
  const double a = w.amplitude, b = w.quadrature;
  return std::isfinite(a) && std::isfinite(b) && std::isfinite(w.theta) && std::isfinite(w.phase) && a * a > b * b;
}

WaveParameters advanced(const WaveParameters& w, const WaveRates& r, double h) {
  return {w.amplitude + h * r.amplitude, w.quadrature + h * r.quadrature, w.theta + h * r.theta, w.phase + h * r.phase};
}

}  // namespace

ResonatorDynamics::ResonatorDynamics(const ShellParameters& parameters, const LoopSettings& loops,
                                     const DriveChainErrors& drive, const WaveParameters& initial)
    : resonator_(parameters), loops_(loops), drive_(drive), wave_(initial) {
  if (!standing(initial)) {
    throw std::invalid_argument("resonator initial wave: needs finite values and A^2 > B^2 (a standing wave)");
  }
}

double ResonatorDynamics::referenceFrequency() const {
  return resonator_.parameters().frequency + command_.reference_offset / kTwoPi;
}

WaveFrameForce ResonatorDynamics::realisedForce() const {
  return drive_.onWave(command_.force, std::cos(2.0 * wave_.theta), std::sin(2.0 * wave_.theta));
}

WaveRates ResonatorDynamics::rates(const WaveParameters& w, double body_rate, double angle_rate) const {
  const double c = std::cos(w.theta), s = std::sin(w.theta);
  const double c2 = c * c - s * s, s2 = 2.0 * s * c;
  return resonator_.rates(w, c2, s2, body_rate, drive_.onWave(command_.force, c2, s2), command_.reference_offset,
                          angle_rate);
}

bool ResonatorDynamics::step(double dt, const ResonatorInputs& in) {
  if (!(dt > 0.0) || !std::isfinite(dt)) throw std::invalid_argument("resonator step: dt must be positive and finite");
  const double periods = std::ceil(dt * loops_.settings().control_rate * (1.0 - 1e-12));
  const int n = periods < 1.0 ? 1 : static_cast<int>(periods);
  const double h = dt / n;
  const double slope = (in.body_rate_end - in.body_rate_start) / dt;
  for (int i = 0; i < n; ++i) {
    command_ = loops_.update(wave_, in.virtual_rate, h);
    const double rate0 = in.body_rate_start + slope * (i * h);
    const double rate_mid = rate0 + slope * (0.5 * h), rate1 = rate0 + slope * h;
    const WaveRates k1 = rates(wave_, rate0, in.angle_rate);
    const WaveRates k2 = rates(advanced(wave_, k1, 0.5 * h), rate_mid, in.angle_rate);
    const WaveRates k3 = rates(advanced(wave_, k2, 0.5 * h), rate_mid, in.angle_rate);
    const WaveRates k4 = rates(advanced(wave_, k3, h), rate1, in.angle_rate);
    const double w = h / 6.0;
    WaveParameters next;
    next.amplitude = wave_.amplitude + w * (k1.amplitude + 2.0 * (k2.amplitude + k3.amplitude) + k4.amplitude);
    next.quadrature = wave_.quadrature + w * (k1.quadrature + 2.0 * (k2.quadrature + k3.quadrature) + k4.quadrature);
    next.theta = wave_.theta + w * (k1.theta + 2.0 * (k2.theta + k3.theta) + k4.theta);
    next.phase = wave_.phase + w * (k1.phase + 2.0 * (k2.phase + k3.phase) + k4.phase);
    if (!standing(next)) return false;
    wave_ = next;
    ++control_periods_;
    time_ += h;
  }
  return true;
}

}  // namespace core
}  // namespace hrg_gyro
