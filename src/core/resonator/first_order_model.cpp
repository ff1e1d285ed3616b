#include "hrg_gyro/core/resonator/first_order_model.h"

#include <cmath>
#include <stdexcept>

namespace hrg_gyro {
namespace core {

ResonatorModel firstOrderModel(const ResonatorParameters& p, const LoopSettings& loops, const DriveChainErrors& drive) {
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

}  // namespace core
}  // namespace hrg_gyro
