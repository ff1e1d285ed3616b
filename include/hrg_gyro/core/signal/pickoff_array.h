// The eight capacitive pickoffs around the resonator rim and the channels they form.
//
// Sensor i nominally sits at phi_i = i pi/4. Its real defects (docs/math.md, 'Pickoff defects to first
// order'): an angular
// misplacement delta_i (it reads the rim at phi_i + delta_i), a gain error g_i, the capacitive
// nonlinearity h(r) = r / (1 - r/d0) of a gap d0 (amplitude-to-gap ratio A/d0), and additive white
// noise. The cosine channel is c = (d0 - d2 + d4 - d6)/4, the sine channel s = (d1 - d3 + d5 - d7)/4.
//
// Misplacement and gain map the channels exactly linearly (c~ = a11 c + a12 s, s~ = -a21 c + a22 s);
// linearChannelMap() gives that map on Z so tests can check that the correction matrix P inverts it.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstring>
#include <limits>

#include "hrg_gyro/core/common/double_lanes.h"
#include "hrg_gyro/core/model/wave_parameters.h"

namespace hrg_gyro {
namespace core {

constexpr int kPickoffCount = 8;

struct PickoffDefects {
  std::array<double, kPickoffCount> misplacement{};  ///< delta_i, rad (sensor i at i pi/4 + delta_i)
  std::array<double, kPickoffCount> gain_error{};    ///< g_i: sensor output (1 + g_i) h(r)
  /// Electrode gap d0 in amplitude units (A/d0 = amplitude / gap); infinity means a linear sensor.
  double gap = std::numeric_limits<double>::infinity();
  double noise = 0.0;  ///< standard deviation of the additive noise of one sensor sample, amplitude units
};

/// Half-sums and mean gains that drive the first-order defect formulas (docs/math.md, 'Pickoff defects
/// to first order').
struct PickoffSignature {
  double dc = 0.0;  ///< (delta0 + delta2 + delta4 + delta6) / 2, rad
  double ds = 0.0;  ///< (delta1 + delta3 + delta5 + delta7) / 2, rad
  double gc = 0.0;  ///< mean gain error of the cosine sensors (0, 2, 4, 6)
  double gs = 0.0;  ///< mean gain error of the sine sensors (1, 3, 5, 7)
};

class PickoffArray {
 public:
  explicit PickoffArray(const PickoffDefects& defects);

  const PickoffDefects& defects() const { return defects_; }
  PickoffSignature signature() const;

  /// Noise-free outputs d_i of the eight sensors for the wave at carrier phase (w t), rad.
  std::array<double, kPickoffCount> sensorOutputs(const WaveParameters& wave, double carrier_phase) const;

  /// Channels c, s formed from eight sensor outputs.
  static void formChannels(const std::array<double, kPickoffCount>& d, double* c, double* s);

  /// Hot path of the simulator: noise-free c, s for the pattern components
  ///   x = A cos(wt + tau) cos(theta) - B sin(wt + tau) sin(theta),
  ///   y = A cos(wt + tau) sin(theta) + B sin(wt + tau) cos(theta),
  /// for which sensor i reads r_i = cos(2 psi_i) x + sin(2 psi_i) y (psi_i its true position).
  void channels(double x, double y, double* c, double* s) const {
    // Channel-major copies of the sensor constants (c sensors 0, 2, 4, 6, then s sensors 1, 3, 5,
    // 7): the eight independent divisions go four per lane operation (two SSE2 instructions, or one
    // AVX one in the simulator's AVX2 build), with the same IEEE results as one at a time.
    DoubleLanes4 t[2];
    for (int q = 0; q < 2; ++q) {
      DoubleLanes4 cos2psi, sin2psi, weight;
      std::memcpy(&cos2psi, channel_cos_ + 4 * q, sizeof cos2psi);
      std::memcpy(&sin2psi, channel_sin_ + 4 * q, sizeof sin2psi);
      std::memcpy(&weight, channel_weight_ + 4 * q, sizeof weight);
      const DoubleLanes4 r = cos2psi * x + sin2psi * y;
      t[q] = weight * r / (1.0 - r * inv_gap_);
    }
    // Summed in sensor order, as the definition reads.
    *c = ((t[0][0] + t[0][1]) + t[0][2]) + t[0][3];
    *s = ((t[1][0] + t[1][1]) + t[1][2]) + t[1][3];
  }

  /// Standard deviation of the noise of one channel sample: four independent sensor noises of sigma,
  /// each weighted 1/4, sum to a Gaussian of sigma / 2. The simulator draws that sum directly, which
  /// is identical in distribution to drawing the eight sensor noises and 4x cheaper.
  double channelNoiseSigma() const { return 0.5 * defects_.noise; }

  /// Exact map of misplacement and gain errors on Z = (Ac, Bc, As, Bs): Z_measured = M Z_true
  /// (the capacitive nonlinearity, which is not linear, is left out).
  Eigen::Matrix4d linearChannelMap() const;

 private:
  PickoffDefects defects_;
  std::array<double, kPickoffCount> cos2psi_{}, sin2psi_{}, weight_{};
  alignas(32) double channel_cos_[8] = {};
  alignas(32) double channel_sin_[8] = {};
  alignas(32) double channel_weight_[8] = {};
  double inv_gap_ = 0.0;
};

}  // namespace core
}  // namespace hrg_gyro
