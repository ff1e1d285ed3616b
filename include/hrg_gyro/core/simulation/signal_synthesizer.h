// Signal level of the simulator: one resonator period sampled N times through the eight pickoffs,
// then demodulated, exactly as the paper does it.
//
// Within the period the wave angle moves linearly from the value at the period start to the value
// at its end (A, B and tau are held); sample j is taken at t0 + (j + 1/2) T / N, carrier phase
// 2 pi (j + 1/2) / N. Noise is drawn per channel sample (see PickoffArray::channelNoiseSigma) from
// a seeded generator, so a run is reproducible bit for bit; a period's deviates are drawn in one go
// (GaussianNoise::fill, the same stream). It is the polar method: the ziggurat
// (GaussianNoise::Method::kZiggurat) is cheaper still, but it draws another noise realisation for
// every shipped scenario and seed, and the documented figures of `make run` and the tests were
// measured on this one; switching is a deliberate, separately measured change.
#pragma once

#include <cstdint>
#include <vector>

#include "hrg_gyro/core/model/wave_parameters.h"
#include "hrg_gyro/core/signal/pickoff_array.h"
#include "hrg_gyro/core/signal/synchronous_demodulator.h"
#include "hrg_gyro/core/simulation/gaussian_noise.h"

namespace hrg_gyro {
namespace core {

class SignalSynthesizer {
 public:
  SignalSynthesizer(const PickoffDefects& defects, int samples_per_period, std::uint64_t seed);

  const PickoffArray& pickoffs() const { return pickoffs_; }
  int samplesPerPeriod() const { return demodulator_.samplesPerPeriod(); }

  /// Channel amplitudes of one period; theta goes from wave.theta to theta_end.
  ChannelVector period(const WaveParameters& wave, double theta_end);

  /// Replaces the pickoff defects (temperature-dependent defects) keeping the noise generator state.
  void setDefects(const PickoffDefects& defects) { pickoffs_ = PickoffArray(defects); }

 private:
  PickoffArray pickoffs_;
  SynchronousDemodulator demodulator_;
  GaussianNoise noise_;
  std::vector<double> noise_buffer_;                                    // one period's deviates
  double carrier_phase_ = 0.0, carrier_cos_ = 1.0, carrier_sin_ = 0.0;  // tau and its cos, sin
};

}  // namespace core
}  // namespace hrg_gyro
