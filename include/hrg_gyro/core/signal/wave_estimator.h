// The whole-angle wave state (Lynch) computed from one set of channel amplitudes Z.
//
//   E = Ac^2+Bc^2+As^2+Bs^2 = A^2+B^2          Q = 2(Ac Bs - As Bc) = 2AB
//   R = Ac^2+Bc^2-As^2-Bs^2 = (A^2-B^2) cos 2th S = 2(Ac As + Bc Bs) = (A^2-B^2) sin 2th
//   L = 2(Ac Bc + As Bs)    = -(A^2-B^2) sin 2tau
// theta = atan2(S, R) / 2 (the paper's X = S/2, Y = R/2 and piecewise arctan). theta is undefined
// when A^2 - B^2 -> 0 (a travelling, not standing, wave); such input, an empty signal and non-finite
// numbers are reported by status and never produce a NaN.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>

#include "hrg_gyro/core/common/double_lanes.h"
#include "hrg_gyro/core/common/fast_atan2.h"
#include "hrg_gyro/core/common/units.h"
#include "hrg_gyro/core/model/correction_matrix.h"
#include "hrg_gyro/core/model/wave_parameters.h"

namespace hrg_gyro {
namespace core {

enum class WaveStatus : std::uint8_t {
  kOk = 0,
  kNonFinite,            ///< a channel amplitude is NaN or infinite (or E overflowed)
  kNoSignal,             ///< energy below the floor: nothing vibrates
  kDegenerate,           ///< (A^2 - B^2)/(A^2 + B^2) below the floor: theta undefined
  kAmplitudeOutOfRange,  ///< A outside the configured plausible range
};
const char* toString(WaveStatus status);

struct WaveLimits {
  double min_energy = 1e-12;    ///< amplitude units squared
  double min_anisotropy = 0.2;  ///< floor of (A^2 - B^2)/(A^2 + B^2); 0.2 means B/A < 0.82
  double min_amplitude = 1e-6;  ///< amplitude units
  double max_amplitude = 1e6;   ///< amplitude units
};

struct WaveState {
  double theta = 0.0;               ///< electrical angle, rad; principal value in (-pi/2, pi/2] until rebased
  double amplitude = 0.0;           ///< A >= 0
  double quadrature = 0.0;          ///< B, with the sign of Q
  double phase = 0.0;               ///< temporal phase tau, rad, in (-pi, pi]
  double energy = 0.0;              ///< E
  double quadrature_product = 0.0;  ///< Q
  double cos_component = 0.0;       ///< R
  double sin_component = 0.0;       ///< S
  double phase_error = 0.0;         ///< L
  /// cos and sin of theta (follow rebase): the compensator builds its harmonics from them with
  /// products instead of a sincos per sample.
  double cos_theta = 1.0, sin_theta = 0.0;

  /// Moves theta to theta + n pi (as the unwrapper decides) and keeps the phase consistent with it:
  /// (A, theta + pi, tau + pi) is the same wave as (A, theta, tau).
  void rebase(double continuous_theta) { rebase(continuous_theta, roundHalfAway((continuous_theta - theta) / kPi)); }
  /// The same when the number of half turns n is known (ThetaUnwrapper::peek gives it).
  void rebase(double continuous_theta, double half_turns) {
    if (std::abs(half_turns) < 0x1p62 && (static_cast<std::int64_t>(half_turns) & 1)) {
      // tau + pi wrapped to (-pi, pi]: one subtraction for a phase already in range.
      if (phase > -kPi && phase <= kPi) {
        phase = phase > 0.0 ? phase - kPi : phase + kPi;
      } else {
        phase = wrapToPi(phase + kPi);
      }
      cos_theta = -cos_theta;
      sin_theta = -sin_theta;
    }
    theta = continuous_theta;
  }
};

namespace wave_detail {

/// The wave state's numbers for one sample (V = double) or a lane of samples (V = DoubleLanes4).
template <class V>
struct WaveLanes {
  V e, r, s, h, q, l, m, theta, amplitude, quadrature, phase, cos_theta, sin_theta;
};

/// Two independent atan2 of one sample in the two lanes of a pair, so that each division of the
/// reduction is one instruction for both; for lanes of samples, one after the other. The same
/// operations either way, so the same bits.
template <class V>
inline void atan2Pair(V y0, V x0, V y1, V x1, V* a0, V* a1) {
  *a0 = fastAtan2Reduced(y0, x0);
  *a1 = fastAtan2Reduced(y1, x1);
}
inline void atan2Pair(double y0, double x0, double y1, double x1, double* a0, double* a1) {
  const DoubleLanes2 a = fastAtan2Reduced(DoubleLanes2{y0, y1}, DoubleLanes2{x0, x1});
  *a0 = a[0];
  *a1 = a[1];
}
/// The same for two independent square roots.
template <class V>
inline void sqrtPair(V x0, V x1, V* r0, V* r1) {
  *r0 = laneSqrt(x0);
  *r1 = laneSqrt(x1);
}
inline void sqrtPair(double x0, double x1, double* r0, double* r1) {
  const DoubleLanes2 r = laneSqrt(DoubleLanes2{x0, x1});
  *r0 = r[0];
  *r1 = r[1];
}

/// The wave state of (corrected) channel amplitudes, valid where waveComputable() holds; the
/// caller checks the status conditions. Every operation is elementwise, so a lane gets the bits
/// one sample gets. Always inline: the inliner may decline for the size, and a call would pass
/// the lanes through memory (and from the AVX2 build into baseline code).
template <class V>
__attribute__((always_inline)) inline void computeWave(V ac, V bc, V as, V bs, WaveLanes<V>* w) {
  w->e = ac * ac + bc * bc + as * as + bs * bs;
  w->r = ac * ac + bc * bc - as * as - bs * bs;
  w->s = 2.0 * (ac * as + bc * bs);
  w->q = 2.0 * (ac * bs - as * bc);
  w->l = 2.0 * (ac * bc + as * bs);
  // Ac^2 - Bc^2 + As^2 - Bs^2 = (A^2 - B^2) cos 2tau: with L, the doubled temporal phase straight
  // from the channels, so its atan2 runs beside theta's instead of after the square roots.
  const V m = ac * ac - bc * bc + as * as - bs * bs;
  w->m = m;
  V doubled_theta, tau2;
  atan2Pair(w->s, w->r, -w->l, m, &doubled_theta, &tau2);
  w->theta = 0.5 * doubled_theta;
  // A^2 - B^2. r^2 + s^2 <= e^2 neither overflows nor, unless the wave is degenerate, underflows
  // where the wave is computable (1e-140 < e < 1e150).
  const V h = laneSqrt(w->r * w->r + w->s * w->s);
  w->h = h;
  const V half_difference = 0.5 * (w->e - h);
  V b;
  sqrtPair(0.5 * (w->e + h), select(0.0 < half_difference, half_difference, splat<V>(0.0)), &w->amplitude, &b);
  w->quadrature = laneCopysign(b, w->q);
  // (cos th, sin th) up to a positive factor, from the half-angle identities
  // tan th = s / (h + r) = (h - r) / s, taking the better-conditioned one: no trigonometry.
  const auto r_non_negative = w->r >= 0.0;
  const V ct = select(r_non_negative, h + w->r, laneAbs(w->s));
  const V st = select(r_non_negative, w->s, laneCopysign(h - w->r, w->s));
  const V norm = 1.0 / laneSqrt(ct * ct + st * st);
  w->cos_theta = ct * norm;
  w->sin_theta = st * norm;
  // tau is half the doubled phase or that +- pi: the channels rotated onto the antinode give
  // Ac cos th + As sin th = A cos tau and Bc cos th + Bs sin th = -A sin tau (docs/math.md's channel
  // amplitudes with the quadrature terms cancelling), and the half angle of (m, -l), up to a
  // positive factor as above (|(m, -l)| = h), must point the same way.
  const V half = 0.5 * tau2;
  const auto m_non_negative = m >= 0.0;
  const V hc = select(m_non_negative, h + m, laneAbs(w->l));
  const V hs = select(m_non_negative, -w->l, laneCopysign(h - m, -w->l));
  const V along = (ac * ct + as * st) * hc - (bc * ct + bs * st) * hs;
  w->phase = select(along < 0.0, select(half > 0.0, half - 3.141592653589793, half + 3.141592653589793), half);
}

/// computeWave's numbers stand for the sample: they are within the range its arithmetic assumes (a
/// sample outside it gets the general path). A bool for one sample, a mask for lanes.
template <class V>
inline auto waveComputable(const WaveLanes<V>& w) {
  return (w.e < 1e150) & (w.e > 1e-140) & fastAtan2Applies(w.s, w.r) & fastAtan2Applies(-w.l, w.m);
}

/// The status checks that follow the finiteness and energy checks, on computable numbers: the
/// wave is not degenerate and its amplitude is in range (a bool or a mask, as above).
template <class V>
inline auto waveAcceptable(const WaveLanes<V>& w, const WaveLimits& limits) {
  return (w.h > limits.min_anisotropy * w.e) &
         ((w.amplitude >= limits.min_amplitude) & (w.amplitude <= limits.max_amplitude));
}

inline void store(const WaveLanes<double>& w, WaveState* state) {
  WaveState& out = *state;
  out.theta = w.theta;
  out.amplitude = w.amplitude;
  out.quadrature = w.quadrature;
  out.phase = w.phase;
  out.energy = w.e;
  out.quadrature_product = w.q;
  out.cos_component = w.r;
  out.sin_component = w.s;
  out.phase_error = w.l;
  out.cos_theta = w.cos_theta;
  out.sin_theta = w.sin_theta;
}

/// The wave state of finite amplitudes so large or small that computeWave's arithmetic would
/// overflow or lose digits: computeWave on the amplitudes scaled by a power of two (exact), the
/// results scaled back. Not a hot path.
WaveStatus estimateWaveGeneral(double ac, double bc, double as, double bs, const WaveLimits& limits, WaveState* state);

}  // namespace wave_detail

/// Fills *state (when the status is kOk) from the channel amplitudes. Inline: it is most of the
/// per-sample step.
__attribute__((always_inline)) inline WaveStatus estimateWave(const ChannelVector& z, const WaveLimits& limits,
                                                              WaveState* state) {
  const double ac = z[kAc], bc = z[kBc], as = z[kAs], bs = z[kBs];
  wave_detail::WaveLanes<double> w;
  wave_detail::computeWave(ac, bc, as, bs, &w);
  if (!std::isfinite(w.e)) {
    // Any NaN or infinite component; else finite amplitudes so huge (1e300) that their energy
    // overflows: those are a value out of range, not a non-finite input.
    const bool finite = std::isfinite(ac) && std::isfinite(bc) && std::isfinite(as) && std::isfinite(bs);
    return finite ? WaveStatus::kAmplitudeOutOfRange : WaveStatus::kNonFinite;
  }
  if (w.e <= limits.min_energy) return WaveStatus::kNoSignal;
  if (!wave_detail::waveComputable(w)) {
    return wave_detail::estimateWaveGeneral(ac, bc, as, bs, limits, state);
  }
  if (!(w.h > limits.min_anisotropy * w.e)) return WaveStatus::kDegenerate;
  if (!wave_detail::waveAcceptable(w, limits)) return WaveStatus::kAmplitudeOutOfRange;
  wave_detail::store(w, state);
  return WaveStatus::kOk;
}

/// estimateWave(correction.apply(z_i)) for n samples at once, four lanes at a time (AVX2 where the
/// CPU has it, chosen at run time), the correction in the same lanes: statuses[i] and the i-th
/// state are bit for bit what one sample gets. The z_i are `z_stride` bytes apart and the states
/// `state_stride` bytes apart: arrays of them, or fields of larger records (GyroProcessor::
/// processBatch reads its samples and estimates straight into its results).
void estimateWaves(const ChannelVector* z, std::size_t z_stride, const CorrectionMatrix& correction, std::size_t n,
                   const WaveLimits& limits, WaveState* states, std::size_t state_stride, WaveStatus* statuses);

}  // namespace core
}  // namespace hrg_gyro
