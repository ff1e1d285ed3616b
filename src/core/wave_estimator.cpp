#include "hrg_gyro/core/wave_estimator.h"

#include <algorithm>
#include <cmath>

#include "hrg_gyro/core/units.h"

namespace hrg_gyro {
namespace core {

const char* toString(WaveStatus status) {
  switch (status) {
    case WaveStatus::kOk: return "ok";
    case WaveStatus::kNonFinite: return "non-finite channel amplitude";
    case WaveStatus::kNoSignal: return "no signal (energy below floor)";
    case WaveStatus::kDegenerate: return "degenerate wave (A close to B, theta undefined)";
    case WaveStatus::kAmplitudeOutOfRange: return "amplitude out of range";
  }
  return "unknown";
}

void WaveState::rebase(double continuous_theta) {
  const double half_turns = std::round((continuous_theta - theta) / kPi);
  if (std::fmod(std::abs(half_turns), 2.0) == 1.0) phase = wrapToPi(phase + kPi);
  theta = continuous_theta;
}

WaveStatus estimateWave(const ChannelVector& z, const WaveLimits& limits, WaveState* state) {
  const double ac = z[kAc], bc = z[kBc], as = z[kAs], bs = z[kBs];
  const double e = ac * ac + bc * bc + as * as + bs * bs;
  if (!std::isfinite(e)) return WaveStatus::kNonFinite;  // also catches any NaN component
  if (e <= limits.min_energy) return WaveStatus::kNoSignal;
  const double r = ac * ac + bc * bc - as * as - bs * bs;
  const double s = 2.0 * (ac * as + bc * bs);
  const double h = std::hypot(r, s);  // A^2 - B^2
  if (!(h > limits.min_anisotropy * e)) return WaveStatus::kDegenerate;
  const double a = std::sqrt(0.5 * (e + h));
  if (a < limits.min_amplitude || a > limits.max_amplitude) return WaveStatus::kAmplitudeOutOfRange;

  const double q = 2.0 * (ac * bs - as * bc);
  WaveState w;
  w.theta = 0.5 * std::atan2(s, r);
  w.amplitude = a;
  w.quadrature = std::copysign(std::sqrt(std::max(0.0, 0.5 * (e - h))), q);
  w.energy = e;
  w.quadrature_product = q;
  w.cos_component = r;
  w.sin_component = s;
  w.phase_error = 2.0 * (ac * bc + as * bs);
  // Rotate the channels onto the antinode: Ac cos th + As sin th = A cos tau and
  // Bc cos th + Bs sin th = -A sin tau (MATH.md section 2 with the quadrature terms cancelling).
  const double ct = std::cos(w.theta), st = std::sin(w.theta);
  w.phase = std::atan2(-(bc * ct + bs * st), ac * ct + as * st);
  *state = w;
  return WaveStatus::kOk;
}

}  // namespace core
}  // namespace hrg_gyro
