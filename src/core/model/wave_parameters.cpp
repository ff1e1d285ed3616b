#include "hrg_gyro/core/model/wave_parameters.h"

#include <cmath>

namespace hrg_gyro {
namespace core {

ChannelVector idealChannels(const WaveParameters& w) {
  const double ct = std::cos(w.theta), st = std::sin(w.theta);
  const double cp = std::cos(w.phase), sp = std::sin(w.phase);
  const double a = w.amplitude, b = w.quadrature;
  ChannelVector z;
  z[kAc] = a * ct * cp - b * st * sp;
  z[kBc] = -a * ct * sp - b * st * cp;
  z[kAs] = a * st * cp + b * ct * sp;
  z[kBs] = -a * st * sp + b * ct * cp;
  return z;
}

double quadratureRatio(double quadrature, double amplitude) {
  if (!(amplitude > 0.0) || !std::isfinite(amplitude) || !std::isfinite(quadrature)) return NAN;
  return quadrature / amplitude;
}

}  // namespace core
}  // namespace hrg_gyro
