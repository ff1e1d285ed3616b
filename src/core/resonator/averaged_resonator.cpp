#include "hrg_gyro/core/resonator/averaged_resonator.h"

#include <cmath>

namespace hrg_gyro {
namespace core {

// The averaged model in complex form: with X, Y the complex amplitudes of x and y on the carrier,
// (X, Y) = e^(i tau) (A u - i B v), u = (cos th, sin th), v = (-sin th, cos th), a force F enters as
// d(X, Y)/dt += -i F / (2 w0). Its share in the wave frame is e^(-i tau) (-i / (2 w0)) F = alpha u + beta v,
// and alpha = a_v + i a_d, beta = n_v - i n_d. Real arithmetic throughout: a complex product would
// call the library's NaN-checking multiply on this path.
WaveFrameForce toWaveFrame(const ModalForce& f, double cos_theta, double sin_theta, double cos_tau, double sin_tau,
                           double w0) {
  const double scale = -0.5 / w0;
  const double a = scale * sin_tau, b = scale * cos_tau;  // e^(-i tau) (-i / (2 w0)) = a + i b
  const double px_re = a * f.x_re - b * f.x_im, px_im = a * f.x_im + b * f.x_re;
  const double py_re = a * f.y_re - b * f.y_im, py_im = a * f.y_im + b * f.y_re;
  WaveFrameForce w;
  w.antinode_velocity = cos_theta * px_re + sin_theta * py_re;
  w.antinode_displacement = cos_theta * px_im + sin_theta * py_im;
  w.node_velocity = -sin_theta * px_re + cos_theta * py_re;
  w.node_displacement = sin_theta * px_im - cos_theta * py_im;
  return w;
}

ModalForce toModalForce(const WaveFrameForce& w, double cos_theta, double sin_theta, double cos_tau, double sin_tau,
                        double w0) {
  // alpha u + beta v, then times 2 i w0 e^(i tau) = c + i d.
  const double alpha_re = w.antinode_velocity, alpha_im = w.antinode_displacement;
  const double beta_re = w.node_velocity, beta_im = -w.node_displacement;
  const double gx_re = alpha_re * cos_theta - beta_re * sin_theta, gx_im = alpha_im * cos_theta - beta_im * sin_theta;
  const double gy_re = alpha_re * sin_theta + beta_re * cos_theta, gy_im = alpha_im * sin_theta + beta_im * cos_theta;
  const double c = -2.0 * w0 * sin_tau, d = 2.0 * w0 * cos_tau;
  ModalForce f;
  f.x_re = c * gx_re - d * gx_im;
  f.x_im = c * gx_im + d * gx_re;
  f.y_re = c * gy_re - d * gy_im;
  f.y_im = c * gy_im + d * gy_re;
  return f;
}

AveragedResonator::AveragedResonator(const ShellParameters& parameters) : parameters_(parameters) {
  parameters_.validate();
  w0_ = parameters_.angularFrequency();
  inverse_damping_time_ = 1.0 / parameters_.damping_time;
  half_h_ = 0.5 * parameters_.damping_anisotropy;
  half_dw_ = 0.5 * parameters_.frequency_split;
  k0_ = parameters_.scaleFactor();
  cos_damping_axis_ = std::cos(2.0 * parameters_.damping_axis);
  sin_damping_axis_ = std::sin(2.0 * parameters_.damping_axis);
  cos_frequency_axis_ = std::cos(2.0 * parameters_.frequency_axis);
  sin_frequency_axis_ = std::sin(2.0 * parameters_.frequency_axis);
}

WaveRates AveragedResonator::rates(const WaveParameters& wave, double body_rate, const ModalForce& force,
                                   double reference_offset, double angle_rate) const {
  const double cos_theta = std::cos(wave.theta), sin_theta = std::sin(wave.theta);
  const WaveFrameForce f = toWaveFrame(force, cos_theta, sin_theta, std::cos(wave.phase), std::sin(wave.phase), w0_);
  return rates(wave, cos_theta * cos_theta - sin_theta * sin_theta, 2.0 * sin_theta * cos_theta, body_rate, f,
               reference_offset, angle_rate);
}

WaveRates AveragedResonator::rates(const WaveParameters& wave, double c2, double s2, double body_rate,
                                   const WaveFrameForce& f, double reference_offset, double angle_rate) const {
  const double a = wave.amplitude, b = wave.quadrature;
  // cos, sin of 2 (theta - axis) for either defect's axis.
  const double cos_dt = c2 * cos_damping_axis_ + s2 * sin_damping_axis_;
  const double sin_dt = s2 * cos_damping_axis_ - c2 * sin_damping_axis_;
  const double cos_dw = c2 * cos_frequency_axis_ + s2 * sin_frequency_axis_;
  const double sin_dw = s2 * cos_frequency_axis_ - c2 * sin_frequency_axis_;
  const double e = a * a + b * b, inverse_w = 1.0 / (a * a - b * b), ab = a * b;
  WaveRates r;
  r.amplitude = -a * inverse_damping_time_ - half_h_ * a * cos_dt - half_dw_ * b * sin_dw + f.antinode_velocity;
  r.quadrature = -b * inverse_damping_time_ + half_h_ * b * cos_dt + half_dw_ * a * sin_dw + f.node_displacement;
  r.theta = k0_ * body_rate + angle_rate +
            (half_h_ * e * sin_dt - 2.0 * half_dw_ * ab * cos_dw + a * f.node_velocity - b * f.antinode_displacement) *
                inverse_w;
  r.phase = -reference_offset +
            (-2.0 * half_h_ * ab * sin_dt + half_dw_ * e * cos_dw + a * f.antinode_displacement - b * f.node_velocity) *
                inverse_w;
  return r;
}

}  // namespace core
}  // namespace hrg_gyro
