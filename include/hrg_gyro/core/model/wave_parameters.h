// The standing wave of the resonator's second mode and the exact channel amplitudes it produces.
//
// Deflection at case angle phi (docs/math.md, 'The standing wave'):
//   r(t, phi) = A cos(2 phi - theta) cos(w t + tau) + B sin(2 phi - theta) sin(w t + tau)
// theta is the electrical wave angle (antinode at phi = theta / 2), A the main amplitude, B the
// quadrature amplitude and tau the temporal phase. An ideal pickoff and demodulator turn this wave
// into Z = (Ac, Bc, As, Bs) with the closed form of docs/math.md, 'Channel amplitudes' (the paper's
// printed set has the sign of tau flipped and cos/sin swapped in Bs). Z_m of the correction-matrix
// fit is this map.
#pragma once

#include <Eigen/Core>

namespace hrg_gyro {
namespace core {

/// Channel amplitudes Z = (Ac, Bc, As, Bs): in-phase and quadrature demodulated amplitudes of the
/// cosine channel (c) and the sine channel (s), in amplitude units.
using ChannelVector = Eigen::Vector4d;
enum ChannelIndex { kAc = 0, kBc = 1, kAs = 2, kBs = 3 };

struct WaveParameters {
  double amplitude = 1.0;   ///< A, amplitude units (the simulator normalises A to 1)
  double quadrature = 0.0;  ///< B, amplitude units
  double theta = 0.0;       ///< electrical wave angle, rad
  double phase = 0.0;       ///< temporal phase tau, rad
};

/// Exact demodulated channel amplitudes of an ideal pickoff for the given wave (docs/math.md,
/// 'Channel amplitudes').
ChannelVector idealChannels(const WaveParameters& wave);

/// B/A of a wave, as the calibration averages it for the defect diagnosis: NaN (not averaged)
/// when the amplitude is not positive or either value is not finite.
double quadratureRatio(double quadrature, double amplitude);

}  // namespace core
}  // namespace hrg_gyro
