#include "hrg_gyro/core/resonator/steady_state_response.h"

#include <cmath>
#include <stdexcept>

namespace hrg_gyro {
namespace core {

SteadyStateResponse::SteadyStateResponse(const ShellParameters& parameters, const LoopSettings& loops,
                                         const DriveChainErrors& drive)
    : parameters_(parameters), drive_(drive) {
  parameters_.validate();
  loops.validate();
  drive_.validate();
  if (loops.quadrature_bandwidth <= 0.0) {
    throw std::invalid_argument("steady-state response: needs the quadrature loop closed (B is not held otherwise)");
  }
  energy_loop_ = loops.energy_bandwidth > 0.0;
  c_ = std::cos(drive_.phase_error);
  s_ = std::sin(drive_.phase_error);
}

SteadyStateResponse::Terms SteadyStateResponse::terms(double theta) const {
  const double g = 0.5 * (drive_.gain_error_c + drive_.gain_error_s);
  const double gamma = 0.5 * (drive_.gain_error_c - drive_.gain_error_s);
  const double dt = 2.0 * (theta - parameters_.damping_axis), dw = 2.0 * (theta - parameters_.frequency_axis);
  const double h = parameters_.damping_anisotropy;
  Terms t;
  t.p = 1.0 + g + gamma * std::cos(2.0 * theta);
  t.q = 1.0 + g - gamma * std::cos(2.0 * theta);
  t.r = gamma * std::sin(2.0 * theta);
  t.rho = 1.0 / parameters_.damping_time + 0.5 * h * std::cos(dt);
  t.sigma = 0.5 * parameters_.frequency_split * std::sin(dw);
  t.half_h_sin_dt = 0.5 * h * std::sin(dt);
  return t;
}

double SteadyStateResponse::drift(double theta) const {
  const Terms t = terms(theta);
  if (!energy_loop_) return t.half_h_sin_dt + t.sigma * s_ / c_;
  const double det = c_ * c_ * t.p * t.q + s_ * s_ * t.r * t.r;
  return t.half_h_sin_dt + (t.sigma * s_ * c_ * (t.p * t.q - t.r * t.r) - t.rho * t.r * t.q) / det;
}

double SteadyStateResponse::virtualRateGain(double theta) const {
  const Terms t = terms(theta);
  const double scale = 1.0 + drive_.virtual_rate_gain_error;
  if (!energy_loop_) return scale * t.q / c_;
  const double det = c_ * c_ * t.p * t.q + s_ * s_ * t.r * t.r;
  return scale * c_ * t.q * (t.p * t.q - t.r * t.r) / det;
}

}  // namespace core
}  // namespace hrg_gyro
