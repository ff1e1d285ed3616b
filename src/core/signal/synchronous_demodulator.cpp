#include "hrg_gyro/core/signal/synchronous_demodulator.h"

#include <cmath>
#include <stdexcept>
#include <string>

#include "hrg_gyro/core/common/units.h"

namespace hrg_gyro {
namespace core {

SynchronousDemodulator::SynchronousDemodulator(int samples_per_period) : n_(samples_per_period) {
  if (n_ < 3) {
    throw std::invalid_argument("samples per period must be >= 3 for the demodulation sums to be exact, got " +
                                std::to_string(n_));
  }
  cos_.resize(n_);
  sin_.resize(n_);
  for (int j = 0; j < n_; ++j) {
    cos_[j] = std::cos(carrierPhase(j));
    sin_[j] = std::sin(carrierPhase(j));
  }
}

// Mid-interval sampling: the N samples are centred on the period, so the amplitudes describe the
// wave at the period's centre (a grid starting at the period start would lag it by T / 2N).
double SynchronousDemodulator::carrierPhase(int j) const { return kTwoPi * (j + 0.5) / n_; }

ChannelVector SynchronousDemodulator::demodulate(const double* c, const double* s) const {
  ChannelVector acc = ChannelVector::Zero();
  for (int j = 0; j < n_; ++j) {
    acc[kAc] += c[j] * cos_[j];
    acc[kBc] += c[j] * sin_[j];
    acc[kAs] += s[j] * cos_[j];
    acc[kBs] += s[j] * sin_[j];
  }
  return acc * (2.0 / n_);
}

}  // namespace core
}  // namespace hrg_gyro
