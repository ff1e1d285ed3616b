#include "hrg_gyro/core/signal/wave_estimator.h"

#include <algorithm>
#include <cmath>

#include "hrg_gyro/core/common/fast_atan2.h"
#include "hrg_gyro/core/common/units.h"

namespace hrg_gyro {
namespace core {

const char* toString(WaveStatus status) {
  switch (status) {
    case WaveStatus::kOk:
      return "ok";
    case WaveStatus::kNonFinite:
      return "non-finite channel amplitude";
    case WaveStatus::kNoSignal:
      return "no signal (energy below floor)";
    case WaveStatus::kDegenerate:
      return "degenerate wave (A close to B, theta undefined)";
    case WaveStatus::kAmplitudeOutOfRange:
      return "amplitude out of range";
  }
  return "unknown";
}

WaveStatus estimateWave(const ChannelVector& z, const WaveLimits& limits, WaveState* state) {
  const double ac = z[kAc], bc = z[kBc], as = z[kAs], bs = z[kBs];
  const double e = ac * ac + bc * bc + as * as + bs * bs;
  if (!std::isfinite(e)) {
    // Any NaN or infinite component; else finite amplitudes so huge (1e300) that their energy
    // overflows: those are a value out of range, not a non-finite input.
    const bool finite = std::isfinite(ac) && std::isfinite(bc) && std::isfinite(as) && std::isfinite(bs);
    return finite ? WaveStatus::kAmplitudeOutOfRange : WaveStatus::kNonFinite;
  }
  if (e <= limits.min_energy) return WaveStatus::kNoSignal;
  const double r = ac * ac + bc * bc - as * as - bs * bs;
  const double s = 2.0 * (ac * as + bc * bs);
  // A^2 - B^2. r^2 + s^2 <= e^2 cannot overflow for the amplitudes a pickoff can report; hypot
  // (several times slower) only guards the absurd range.
  const double h = e < 1e150 ? std::sqrt(r * r + s * s) : std::hypot(r, s);
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
  // Bc cos th + Bs sin th = -A sin tau (the channel amplitudes of docs/math.md with the quadrature
  // terms cancelling).
  // (cos th, sin th) up to a positive factor, which atan2 ignores, from the half-angle identities
  // tan th = s / (h + r) = (h - r) / s, taking the better-conditioned one: no trigonometry.
  double ct, st;
  if (r >= 0.0) {
    ct = h + r;
    st = s;
  } else {
    ct = std::abs(s);
    st = std::copysign(h - r, s);
  }
  // The phase is a diagnostic (published, never integrated): the inline atan2, within 1e-15 rad of the
  // library's, halves its cost. theta, which is integrated, keeps the library's atan2.
  w.phase = fastAtan2(-(bc * ct + bs * st), ac * ct + as * st);
  const double norm = 1.0 / std::sqrt(ct * ct + st * st);
  w.cos_theta = ct * norm;
  w.sin_theta = st * norm;
  *state = w;
  return WaveStatus::kOk;
}

}  // namespace core
}  // namespace hrg_gyro
