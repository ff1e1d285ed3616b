#include "hrg_gyro/core/resonator/first_order_model.h"

#include <cmath>
#include <stdexcept>

namespace hrg_gyro {
namespace core {

ResonatorModel firstOrderModel(const ShellParameters& p, const LoopSettings& loops, const DriveChainErrors& drive) {
  p.validate();
  loops.validate();
  drive.validate();
  const double split = p.frequency_split;
  if (loops.quadrature_bandwidth <= 0.0 && split != 0.0) {
    throw std::invalid_argument("first-order model: a frequency split needs the quadrature loop closed");
  }
  const double half_h = 0.5 * p.damping_anisotropy;
  const double split_phase = 0.5 * split * drive.phase_error;
  const double gamma = 0.5 * (drive.gain_error_c - drive.gain_error_s);
  const double g = 0.5 * (drive.gain_error_c + drive.gain_error_s);
  const double leak = loops.energy_bandwidth > 0.0 ? gamma / p.damping_time : 0.0;
  const double ta = 2.0 * p.damping_axis, wa = 2.0 * p.frequency_axis;
  ResonatorModel m;
  // a sin 2(theta - x) = a (sin 2theta cos 2x - cos 2theta sin 2x)
  m.drift = HarmonicModel({2}, 0.0, {-half_h * std::sin(ta) - split_phase * std::sin(wa)},
                          {half_h * std::cos(ta) + split_phase * std::cos(wa) - leak});
  const double ki = loops.integralGain(loops.quadrature_bandwidth);
  m.quadrature_lag = split == 0.0 ? 0.0 : split * split / (2.0 * ki);
  const double lag = m.quadrature_lag, k0 = p.scaleFactor();
  m.scale_factor =
      HarmonicModel({4}, k0 * (1.0 - lag), {-k0 * lag * std::cos(2.0 * wa)}, {-k0 * lag * std::sin(2.0 * wa)});
  m.virtual_rate_gain = HarmonicModel({2, 4}, 1.0 + drive.virtual_rate_gain_error + g - lag,
                                      {-gamma, -lag * std::cos(2.0 * wa)}, {0.0, -lag * std::sin(2.0 * wa)});
  return m;
}

namespace {

// A loop's closed-loop response at s = i omega, as the two parts the lag terms need:
// Re T - 1 = omega^2 (ki - omega^2) / Den and -Im T = kp omega^3 / Den; also kp omega^2 / Den, the
// real part of s / (s^2 + kp s + ki) (what the quadrature loop leaves of its source in B).
struct LoopLag {
  double real_minus_one = 0.0, minus_imaginary = 0.0, trailing = 0.0;
};

LoopLag loopLag(const LoopSettings& loops, double bandwidth, double omega) {
  LoopLag l;
  if (!(bandwidth > 0.0)) return l;  // an open loop has no effort to trail
  const double kp = loops.proportionalGain(bandwidth), ki = loops.integralGain(bandwidth);
  const double o2 = omega * omega, re = ki - o2, im = kp * omega;
  const double den = re * re + im * im;
  l.real_minus_one = o2 * re / den;
  l.minus_imaginary = kp * o2 * omega / den;
  l.trailing = kp * o2 / den;
  return l;
}

}  // namespace

HarmonicModel precessionLagDrift(const ShellParameters& p, const LoopSettings& loops, const DriveChainErrors& drive,
                                 double virtual_rate) {
  firstOrderModel(p, loops, drive);  // the same validation
  if (!std::isfinite(virtual_rate)) throw std::invalid_argument("precession lag: the virtual rate must be finite");
  const double w = virtual_rate, omega = 2.0 * w;
  const double split = p.frequency_split, h = p.damping_anisotropy, phi = drive.phase_error;
  const double gamma = 0.5 * (drive.gain_error_c - drive.gain_error_s);
  const double hc = 1.0 / loops.control_rate;
  const LoopLag q = loopLag(loops, loops.quadrature_bandwidth, omega);
  const LoopLag e = loopLag(loops, loops.energy_bandwidth, omega);
  // Amplitudes of sin 4(theta - theta_omega), sin 2(theta - theta_omega), sin 4theta, sin 2theta and
  // sin 2(theta - theta_d).
  const double split_4 = -0.25 * split * split * q.trailing;
  const double split_phase_2 = 0.5 * phi * split * q.real_minus_one;
  const double imbalance_4 = 0.5 * gamma * gamma * w * e.minus_imaginary;
  const double imbalance_2 = -0.5 * gamma * w * w * hc * e.real_minus_one;
  const double anisotropy_2 = -0.25 * w * h * hc * e.minus_imaginary;
  // a sin k(theta - x) = a (sin k theta cos k x - cos k theta sin k x)
  const double wa2 = 2.0 * p.frequency_axis, wa4 = 4.0 * p.frequency_axis, da2 = 2.0 * p.damping_axis;
  const double cos2 = -split_phase_2 * std::sin(wa2) - anisotropy_2 * std::sin(da2);
  const double sin2 = split_phase_2 * std::cos(wa2) + imbalance_2 + anisotropy_2 * std::cos(da2);
  const double cos4 = -split_4 * std::sin(wa4);
  const double sin4 = split_4 * std::cos(wa4) + imbalance_4;
  return HarmonicModel({2, 4}, 0.0, {cos2, cos4}, {sin2, sin4});
}

}  // namespace core
}  // namespace hrg_gyro
