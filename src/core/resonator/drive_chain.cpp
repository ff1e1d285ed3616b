#include "hrg_gyro/core/resonator/drive_chain.h"

#include <cmath>
#include <stdexcept>
#include <string>

#include "hrg_gyro/core/common/units.h"

namespace hrg_gyro {
namespace core {

void DriveChainErrors::validate() const {
  const auto require = [](bool ok, const char* field, const std::string& what) {
    if (!ok) throw std::invalid_argument(std::string("drive chain ") + field + ": " + what);
  };
  require(std::isfinite(gain_error_c) && gain_error_c > -1.0, "gain_error_c", "must be finite and above -1");
  require(std::isfinite(gain_error_s) && gain_error_s > -1.0, "gain_error_s", "must be finite and above -1");
  require(std::isfinite(phase_error) && std::abs(phase_error) < 0.5 * kPi, "phase_error",
          "must be finite and below pi/2 in magnitude");
  require(std::isfinite(virtual_rate_gain_error) && virtual_rate_gain_error > -1.0, "virtual_rate_gain_error",
          "must be finite and above -1");
}

DriveChain::DriveChain(const DriveChainErrors& errors) : errors_(errors) {
  errors_.validate();
  gain_c_ = 1.0 + errors_.gain_error_c;
  gain_s_ = 1.0 + errors_.gain_error_s;
  mean_ = 1.0 + 0.5 * (errors_.gain_error_c + errors_.gain_error_s);
  half_difference_ = 0.5 * (errors_.gain_error_c - errors_.gain_error_s);
  cos_phase_ = std::cos(errors_.phase_error);
  sin_phase_ = std::sin(errors_.phase_error);
  precession_scale_ = 1.0 + errors_.virtual_rate_gain_error;
}

ModalForce DriveChain::realise(const WaveFrameForce& command, double cos_theta, double sin_theta, double cos_tau,
                               double sin_tau, double w0) const {
  WaveFrameForce scaled = command;
  scaled.node_velocity *= precession_scale_;
  const ModalForce f = toModalForce(scaled, cos_theta, sin_theta, cos_tau, sin_tau, w0);
  // A lag phi multiplies each complex amplitude by e^(-i phi); then each family's gain.
  const double c = cos_phase_, s = sin_phase_;
  ModalForce out;
  out.x_re = gain_c_ * (c * f.x_re + s * f.x_im);
  out.x_im = gain_c_ * (c * f.x_im - s * f.x_re);
  out.y_re = gain_s_ * (c * f.y_re + s * f.y_im);
  out.y_im = gain_s_ * (c * f.y_im - s * f.y_re);
  return out;
}

}  // namespace core
}  // namespace hrg_gyro
