#include "hrg_gyro/core/processing/triad_variance_pairing.h"

#include <cmath>
#include <stdexcept>

#include "hrg_gyro/core/processing/gyro_processor.h"

namespace hrg_gyro {
namespace core {

TriadVariancePairing::TriadVariancePairing(std::size_t max_held)
    : max_held_(max_held), outputs_(max_held + 1), variances_(max_held + 1) {
  if (max_held < 1) throw std::invalid_argument("rate variance pairing: max_held must be at least 1");
}

void TriadVariancePairing::release(AxisOutput output, double variance, std::vector<AxisOutput>* ready) {
  output.rate_variance = variance;
  if (std::isnan(variance)) {
    ++counters_.without_variance;
  } else {
    ++counters_.paired;
  }
  ready->push_back(output);
}

void TriadVariancePairing::addOutput(const AxisOutput& output, std::vector<AxisOutput>* ready) {
  if (has_output_ && output.stamp < last_output_) {
    // A loop: what waits from before it will find no variance any more.
    while (!outputs_.empty()) {
      release(outputs_.front(), NAN, ready);
      outputs_.pop_front();
    }
  }
  has_output_ = true;
  last_output_ = output.stamp;
  outputs_.push_back(output);
  drain(ready);
  if (outputs_.size() > max_held_) {
    release(outputs_.front(), NAN, ready);
    outputs_.pop_front();
    drain(ready);
  }
}

void TriadVariancePairing::addVariance(Nanoseconds stamp, double variance, std::vector<AxisOutput>* ready) {
  if (has_variance_ && stamp < last_variance_) {
    counters_.unmatched_variances += variances_.size();
    variances_.clear();
  }
  has_variance_ = true;
  last_variance_ = stamp;
  variances_.push_back(Variance{stamp, variance});
  drain(ready);
  if (variances_.size() > max_held_) {
    variances_.pop_front();
    ++counters_.unmatched_variances;
  }
}

void TriadVariancePairing::drain(std::vector<AxisOutput>* ready) {
  while (!outputs_.empty()) {
    const AxisOutput& o = outputs_.front();
    if (o.flags & (kFlagGap | kFlagReset)) {  // the processor publishes no Imu for these
      release(o, NAN, ready);
      outputs_.pop_front();
      continue;
    }
    if (variances_.empty()) return;  // its variance may still come
    const Variance v = variances_.front();
    if (v.stamp < o.stamp) {  // the variance of an output that never came
      variances_.pop_front();
      ++counters_.unmatched_variances;
      continue;
    }
    release(o, v.stamp == o.stamp ? v.value : NAN, ready);  // a later one: this output's was lost
    outputs_.pop_front();
    if (v.stamp == o.stamp) variances_.pop_front();
  }
}

}  // namespace core
}  // namespace hrg_gyro
