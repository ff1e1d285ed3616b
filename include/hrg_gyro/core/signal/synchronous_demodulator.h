// Synchronous demodulation of the two channels over whole periods of the resonator.
//
// Ac = (2/T) int c cos(wt), Bc = (2/T) int c sin(wt), and likewise As, Bs from s (docs/math.md,
// 'Channel amplitudes'),
// as sums over N samples per period taken at carrier phases 2 pi (j + 1/2) / N (the reference is
// locked to the resonator, so the sample grid always spans exactly one period, centred on it). The sum is exact for
// every carrier harmonic m with m != +-1 mod N; the capacitive nonlinearity puts energy at the odd harmonics, so N = 4
// aliases the third harmonic onto the fundamental and N >= 8 is required for that reason (the class itself accepts N >=
// 3, where the discrete orthogonality holds, so that tests can show the aliasing).
#pragma once

#include <vector>

#include "hrg_gyro/core/model/wave_parameters.h"

namespace hrg_gyro {
namespace core {

class SynchronousDemodulator {
 public:
  /// Throws std::invalid_argument for fewer than 3 samples per period.
  explicit SynchronousDemodulator(int samples_per_period);

  int samplesPerPeriod() const { return n_; }
  /// Carrier phase of sample j, rad.
  double carrierPhase(int j) const;
  double referenceCos(int j) const { return cos_[j]; }
  double referenceSin(int j) const { return sin_[j]; }

  /// Demodulates one period: c[j], s[j] for j = 0 .. N-1.
  ChannelVector demodulate(const double* c, const double* s) const;

  /// Streaming form: feed samples in order; returns true when a period is complete, whose
  /// amplitudes are then in result() (the accumulator restarts for the next period).
  bool push(double c, double s) {
    acc_[kAc] += c * cos_[j_];
    acc_[kBc] += c * sin_[j_];
    acc_[kAs] += s * cos_[j_];
    acc_[kBs] += s * sin_[j_];
    if (++j_ < n_) return false;
    result_ = acc_ * (2.0 / n_);
    acc_.setZero();
    j_ = 0;
    return true;
  }
  const ChannelVector& result() const { return result_; }
  /// Index of the next sample within the period.
  int phaseIndex() const { return j_; }

 private:
  int n_;
  std::vector<double> cos_, sin_;
  ChannelVector acc_ = ChannelVector::Zero();
  ChannelVector result_ = ChannelVector::Zero();
  int j_ = 0;
};

}  // namespace core
}  // namespace hrg_gyro
