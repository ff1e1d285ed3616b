#include "hrg_gyro/core/signal/wave_estimator.h"

#include <algorithm>

#include "hrg_gyro/core/common/double_lanes.h"

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

namespace wave_detail {

WaveStatus estimateWaveGeneral(double ac, double bc, double as, double bs, const WaveLimits& limits, WaveState* state) {
  const double largest = std::max(std::max(std::abs(ac), std::abs(bc)), std::max(std::abs(as), std::abs(bs)));
  const int exponent = std::ilogb(largest);  // the largest amplitude scaled into [1, 2)
  const double down = std::ldexp(1.0, -exponent);
  WaveLanes<double> w;
  computeWave(ac * down, bc * down, as * down, bs * down, &w);
  // With E >= 1 and A^2 - B^2 > min_anisotropy E, every operand is now in computeWave's range.
  if (!(w.h > limits.min_anisotropy * w.e)) return WaveStatus::kDegenerate;
  w.amplitude = std::ldexp(w.amplitude, exponent);
  if (!waveAcceptable(w, limits)) return WaveStatus::kAmplitudeOutOfRange;
  w.quadrature = std::ldexp(w.quadrature, exponent);
  for (double* squared : {&w.e, &w.r, &w.s, &w.q, &w.l}) *squared = std::ldexp(*squared, 2 * exponent);
  store(w, state);
  return WaveStatus::kOk;
}

}  // namespace wave_detail

// Built twice, for the x86-64 baseline and for AVX2, the loader picking one by CPU: either way each
// lane is computed with the operations estimateWave uses, in the same order, so the same bits.
HRG_GYRO_CLONES_FOR_AVX2 void estimateWaves(const ChannelVector* z, std::size_t z_stride,
                                            const CorrectionMatrix& correction, std::size_t n, const WaveLimits& limits,
                                            WaveState* states, std::size_t state_stride, WaveStatus* statuses) {
  const auto channels = [z, z_stride](std::size_t i) -> const ChannelVector& {
    return *reinterpret_cast<const ChannelVector*>(reinterpret_cast<const char*>(z) + i * z_stride);
  };
  const auto state = [states, state_stride](std::size_t i) {
    return reinterpret_cast<WaveState*>(reinterpret_cast<char*>(states) + i * state_stride);
  };
  constexpr std::size_t kLanes = 4;
  std::size_t i = 0;
  for (; i + kLanes <= n; i += kLanes) {
    DoubleLanes4 ac, bc, as, bs;
    for (std::size_t j = 0; j < kLanes; ++j) {
      const ChannelVector& c = channels(i + j);
      ac[j] = c[kAc];
      bc[j] = c[kBc];
      as[j] = c[kAs];
      bs[j] = c[kBs];
    }
    correction.apply(&ac, &bc, &as, &bs);
    wave_detail::WaveLanes<DoubleLanes4> w;
    wave_detail::computeWave(ac, bc, as, bs, &w);
    // The lanes where estimateWave would take computeWave's numbers and accept them; the others
    // (rare: rejected or extreme values) are estimated one by one.
    const auto accepted =
        wave_detail::waveComputable(w) & (w.e > limits.min_energy) & wave_detail::waveAcceptable(w, limits);
    for (std::size_t j = 0; j < kLanes; ++j) {
      if (!accepted[j]) {
        statuses[i + j] = estimateWave(correction.apply(channels(i + j)), limits, state(i + j));
        continue;
      }
      wave_detail::WaveLanes<double> lane{w.e[j],     w.r[j],         w.s[j],        w.h[j],         w.q[j],
                                          w.l[j],     w.m[j],         w.theta[j],    w.amplitude[j], w.quadrature[j],
                                          w.phase[j], w.cos_theta[j], w.sin_theta[j]};
      wave_detail::store(lane, state(i + j));
      statuses[i + j] = WaveStatus::kOk;
    }
  }
  for (; i < n; ++i) statuses[i] = estimateWave(correction.apply(channels(i)), limits, state(i));
}

}  // namespace core
}  // namespace hrg_gyro
