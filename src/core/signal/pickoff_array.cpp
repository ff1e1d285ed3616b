#include "hrg_gyro/core/signal/pickoff_array.h"

#include <cmath>

#include "hrg_gyro/core/common/units.h"

namespace hrg_gyro {
namespace core {

PickoffArray::PickoffArray(const PickoffDefects& defects) : defects_(defects) {
  for (int i = 0; i < kPickoffCount; ++i) {
    const double psi = i * kPi / 4.0 + defects.misplacement[i];
    cos2psi_[i] = std::cos(2.0 * psi);
    sin2psi_[i] = std::sin(2.0 * psi);
    // Channel sign (+ - + -) and the 1/4 of the channel sum folded into the sensor gain.
    const double sign = (i / 2) % 2 == 0 ? 1.0 : -1.0;
    weight_[i] = sign * (1.0 + defects.gain_error[i]) / 4.0;
  }
  inv_gap_ = std::isfinite(defects.gap) ? 1.0 / defects.gap : 0.0;
  for (int i = 0; i < kPickoffCount; ++i) {
    const int slot = 4 * (i % 2) + i / 2;
    channel_cos_[slot] = cos2psi_[i];
    channel_sin_[slot] = sin2psi_[i];
    channel_weight_[slot] = weight_[i];
  }
}

PickoffSignature PickoffArray::signature() const {
  PickoffSignature sig;
  for (int i = 0; i < kPickoffCount; i += 2) {
    sig.dc += defects_.misplacement[i] / 2.0;
    sig.gc += defects_.gain_error[i] / 4.0;
  }
  for (int i = 1; i < kPickoffCount; i += 2) {
    sig.ds += defects_.misplacement[i] / 2.0;
    sig.gs += defects_.gain_error[i] / 4.0;
  }
  return sig;
}

std::array<double, kPickoffCount> PickoffArray::sensorOutputs(const WaveParameters& wave, double carrier_phase) const {
  const double u = wave.amplitude * std::cos(carrier_phase + wave.phase);
  const double v = wave.quadrature * std::sin(carrier_phase + wave.phase);
  std::array<double, kPickoffCount> d{};
  for (int i = 0; i < kPickoffCount; ++i) {
    const double psi = i * kPi / 4.0 + defects_.misplacement[i];
    // The deflection formula itself, evaluated directly (independent of the x/y fast path).
    const double r = u * std::cos(2.0 * psi - wave.theta) + v * std::sin(2.0 * psi - wave.theta);
    d[i] = (1.0 + defects_.gain_error[i]) * r / (1.0 - r * inv_gap_);
  }
  return d;
}

void PickoffArray::formChannels(const std::array<double, kPickoffCount>& d, double* c, double* s) {
  *c = (d[0] - d[2] + d[4] - d[6]) / 4.0;
  *s = (d[1] - d[3] + d[5] - d[7]) / 4.0;
}

Eigen::Matrix4d PickoffArray::linearChannelMap() const {
  // c~ = a11 c + a12 s and s~ = -a21 c + a22 s (see pickoff_array.h); the same 2x2 map acts on the
  // in-phase pair (Ac, As) and on the quadrature pair (Bc, Bs).
  double a11 = 0.0, a12 = 0.0, a21 = 0.0, a22 = 0.0;
  for (int i = 0; i < kPickoffCount; i += 2) {
    const double g = (1.0 + defects_.gain_error[i]) / 4.0;
    a11 += g * cos2psi_[i] * ((i / 2) % 2 == 0 ? 1.0 : -1.0);
    a12 += g * sin2psi_[i] * ((i / 2) % 2 == 0 ? 1.0 : -1.0);
  }
  for (int i = 1; i < kPickoffCount; i += 2) {
    const double g = (1.0 + defects_.gain_error[i]) / 4.0;
    // Sensor at pi/4 + delta reads cos(2 delta) s - sin(2 delta) c; cos2psi = -sin(2 delta) there.
    a21 -= g * cos2psi_[i] * ((i / 2) % 2 == 0 ? 1.0 : -1.0);
    a22 += g * sin2psi_[i] * ((i / 2) % 2 == 0 ? 1.0 : -1.0);
  }
  Eigen::Matrix4d m = Eigen::Matrix4d::Zero();
  m(kAc, kAc) = a11;
  m(kAc, kAs) = a12;
  m(kBc, kBc) = a11;
  m(kBc, kBs) = a12;
  m(kAs, kAc) = -a21;
  m(kAs, kAs) = a22;
  m(kBs, kBc) = -a21;
  m(kBs, kBs) = a22;
  return m;
}

}  // namespace core
}  // namespace hrg_gyro
