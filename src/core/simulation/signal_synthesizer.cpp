#include "hrg_gyro/core/simulation/signal_synthesizer.h"

#include <cmath>

#include "hrg_gyro/core/common/double_lanes.h"

namespace hrg_gyro {
namespace core {

SignalSynthesizer::SignalSynthesizer(const PickoffDefects& defects, int samples_per_period, std::uint64_t seed)
    : pickoffs_(defects),
      demodulator_(samples_per_period),
      noise_(seed, GaussianNoise::Method::kPolar),
      noise_buffer_(2 * static_cast<std::size_t>(demodulator_.samplesPerPeriod())) {}

// Built for the x86-64 baseline and for AVX2 (chosen at load time): the pickoffs' divisions go four per
// instruction there, with the same IEEE results.
HRG_GYRO_CLONES_FOR_AVX2 ChannelVector SignalSynthesizer::period(const WaveParameters& wave, double theta_end) {
  const int n = demodulator_.samplesPerPeriod();
  const double sigma = pickoffs_.channelNoiseSigma();
  // Carrier: cos(2 pi j/N + tau) and sin(...) by rotating the reference table by tau.
  // tau is held over long stretches: its sincos is kept from the last period while it is unchanged.
  if (!(wave.phase == carrier_phase_)) {
    carrier_phase_ = wave.phase;
    carrier_cos_ = std::cos(wave.phase);
    carrier_sin_ = std::sin(wave.phase);
  }
  const double ctau = carrier_cos_, stau = carrier_sin_;
  // Wave angle at the sample instants (j + 1/2) T / N: rotate (cos theta, sin theta) by a constant
  // step per sample, starting half a step into the period.
  const double step = (theta_end - wave.theta) / n;
  double ct = std::cos(wave.theta + 0.5 * step), st = std::sin(wave.theta + 0.5 * step);
  const double cstep = std::cos(step), sstep = std::sin(step);
  // The period's noise first, in the order the samples take it (c then s): drawn in one go, the
  // deviates' logarithms overlap instead of chaining through the loop below.
  double* noise = noise_buffer_.data();
  if (sigma > 0.0) noise_.fill(noise, 2 * n);
  for (int j = 0; j < n; ++j) {
    const double rc = demodulator_.referenceCos(j), rs = demodulator_.referenceSin(j);
    const double u = wave.amplitude * (rc * ctau - rs * stau);   // A cos(wt + tau)
    const double v = wave.quadrature * (rs * ctau + rc * stau);  // B sin(wt + tau)
    double c, s;
    pickoffs_.channels(u * ct - v * st, u * st + v * ct, &c, &s);
    if (sigma > 0.0) {
      c += sigma * noise[2 * j];
      s += sigma * noise[2 * j + 1];
    }
    demodulator_.push(c, s);
    const double ct_next = ct * cstep - st * sstep;
    st = st * cstep + ct * sstep;
    ct = ct_next;
  }
  return demodulator_.result();  // the N-th push completed the period
}

}  // namespace core
}  // namespace hrg_gyro
