// Test support: a long, reproducible stream of channel samples that exercises every rule of the
// processor: clean samples of a wave turning at a varying rate with noise, interleaved with bad values
// (NaN, infinity, no signal, a degenerate wave, an absurd amplitude), stamp faults (zero, duplicate,
// out of order, single samples stamped far ahead or back, a bag-loop jump back, forward gaps), channel
// sign flips (single glitches and runs long
// enough to re-anchor) and unknown or out-of-range frequencies. Tests compare two ways of running the
// processor over it (one call per sample against the batch entry point, say).
#pragma once

#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <vector>

#include "hrg_gyro/core/common/units.h"
#include "hrg_gyro/core/model/wave_parameters.h"
#include "hrg_gyro/core/processing/gyro_processor.h"

namespace hrg_gyro {
namespace core {
namespace testing {

inline std::vector<ChannelSample> faultyChannelStream(std::size_t n, std::uint64_t seed) {
  std::mt19937_64 random(seed);
  // Uniform in [0, 1) from the raw bits: the same on every standard library.
  auto uniform = [&random]() { return static_cast<double>(random() >> 11) * 0x1.0p-53; };
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  std::vector<ChannelSample> out;
  out.reserve(n);
  Nanoseconds stamp = 1000000000;
  double theta = 0.3, rate = 0.5;  // electrical, rad and rad/s
  int flips_left = 0;
  while (out.size() < n) {
    const double event = uniform();
    Nanoseconds step = 1000000;                                // 1 kHz
    if (event < 0.002) step = 150000000;                       // gap above max_gap
    if (event >= 0.002 && event < 0.0025) step = -2000000000;  // bag loop: reset
    if (uniform() < 0.01) rate = 20.0 * (uniform() - 0.5);     // new electrical rate
    theta += rate * static_cast<double>(step > 0 ? step : 1000000) * 1e-9;
    stamp += step;
    ChannelSample s;
    s.stamp = stamp;
    s.z = idealChannels({1.0 + 0.01 * uniform(), 0.02 + 0.01 * uniform(), theta, 0.3 + 0.1 * uniform()});
    for (int k = 0; k < 4; ++k) s.z[k] += 1e-6 * (uniform() - 0.5);
    s.frequency = 5000.0 + 4.0 * (uniform() - 0.5);
    s.temperature = 25.0;
    const double fault = uniform();
    if (fault < 0.004)
      s.z[static_cast<int>(4.0 * uniform())] = nan;
    else if (fault < 0.006)
      s.z[1] = inf;
    else if (fault < 0.008)
      s.z.setZero();
    else if (fault < 0.010)
      s.z = idealChannels({1.0, 0.95, theta, 0.3});  // A ~ B
    else if (fault < 0.011)
      s.z *= 1e8;  // amplitude out of range
    else if (fault < 0.014)
      s.stamp = 0;
    else if (fault < 0.017 && !out.empty())
      s.stamp = out.back().stamp;  // duplicate
    else if (fault < 0.020 && !out.empty())
      s.stamp = out.back().stamp - 300000;  // out of order
    else if (fault < 0.0205)
      s.stamp += 1000000000000;  // one sample 1000 s ahead
    else if (fault < 0.021)
      s.stamp -= 100000000000;  // one sample 100 s back
    else if (fault < 0.023)
      s.frequency = nan;
    else if (fault < 0.025)
      s.frequency = 7000.0;
    else if (fault < 0.028)
      flips_left = uniform() < 0.5 ? 1 : 8;  // a glitch, or a run that re-anchors
    if (flips_left > 0) {
      s.z[kAc] = -s.z[kAc];  // the cosine channel's sign flipped: theta jumps to -theta
      s.z[kBc] = -s.z[kBc];
      --flips_left;
    }
    out.push_back(s);
  }
  return out;
}

}  // namespace testing
}  // namespace core
}  // namespace hrg_gyro
