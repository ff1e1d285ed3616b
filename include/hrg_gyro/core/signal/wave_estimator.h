// The whole-angle wave state (Lynch) computed from one set of channel amplitudes Z.
//
//   E = Ac^2+Bc^2+As^2+Bs^2 = A^2+B^2          Q = 2(Ac Bs - As Bc) = 2AB
//   R = Ac^2+Bc^2-As^2-Bs^2 = (A^2-B^2) cos 2th S = 2(Ac As + Bc Bs) = (A^2-B^2) sin 2th
//   L = 2(Ac Bc + As Bs)    = -(A^2-B^2) sin 2tau
// theta = atan2(S, R) / 2 (the paper's X = S/2, Y = R/2 and piecewise arctan). theta is undefined
// when A^2 - B^2 -> 0 (a travelling, not standing, wave); such input, an empty signal and non-finite
// numbers are reported by status and never produce a NaN.
#pragma once

#include <cstdint>

#include "hrg_gyro/core/common/units.h"
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
  void rebase(double continuous_theta) {
    const double half_turns = roundHalfAway((continuous_theta - theta) / kPi);
    if (std::abs(half_turns) < 0x1p62 && (static_cast<std::int64_t>(half_turns) & 1)) {
      phase = wrapToPi(phase + kPi);
      cos_theta = -cos_theta;
      sin_theta = -sin_theta;
    }
    theta = continuous_theta;
  }
};

/// Fills *state (when the status is kOk) from the channel amplitudes.
WaveStatus estimateWave(const ChannelVector& z, const WaveLimits& limits, WaveState* state);

}  // namespace core
}  // namespace hrg_gyro
