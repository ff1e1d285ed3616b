// Test support for the resonator: a shell with every defect at a realistic size, its loops and its
// drive chain; and a run of the closed-loop resonator at 1 kHz that records the angle rate of each
// step against the angle at the step's middle.
#pragma once

#include <algorithm>
#include <cmath>
#include <vector>

#include "hrg_gyro/core/common/units.h"
#include "hrg_gyro/core/resonator/resonator_dynamics.h"

namespace hrg_gyro {
namespace core {
namespace testing {

struct ResonatorCase {
  ResonatorParameters shell;
  LoopSettings loops;
  DriveChainErrors drive;

  /// Every defect and drive error times `factor` (the loops unchanged).
  ResonatorCase scaled(double factor) const {
    ResonatorCase c = *this;
    c.shell.damping_anisotropy *= factor;
    c.shell.frequency_split *= factor;
    c.drive.gain_error_c *= factor;
    c.drive.gain_error_s *= factor;
    c.drive.phase_error *= factor;
    c.drive.virtual_rate_gain_error *= factor;
    return c;
  }
};

/// A 5 kHz shell with Q = 9.4e6 (tau_d = 600 s), a damping anisotropy of 4e-5 1/s (2.4 % of 2/tau_d),
/// a 5 mHz split, forcers 2e-3 and -1e-3 off in gain and 1 mrad late, a precession channel 3e-3 off:
/// drift terms of 2e-5, 1.6e-5 and 2.5e-6 rad/s, as in the package's shipped D(theta).
inline ResonatorCase realisticResonator() {
  ResonatorCase c;
  c.shell.frequency = 5000.0;
  c.shell.bryan_factor = 0.28;
  c.shell.damping_time = 600.0;
  c.shell.damping_anisotropy = 4e-5;
  c.shell.damping_axis = 0.4;
  c.shell.frequency_split = kTwoPi * 5e-3;
  c.shell.frequency_axis = -0.7;
  c.drive.gain_error_c = 2e-3;
  c.drive.gain_error_s = -1e-3;
  c.drive.phase_error = 1e-3;
  c.drive.virtual_rate_gain_error = 3e-3;
  return c;
}

/// The angle rate over one step and where the wave was.
struct RateSample {
  double theta = 0.0;  ///< rad, the middle of the step's angle span
  double rate = 0.0;   ///< rad/s, the step's angle increment over its duration
  double span = 0.0;   ///< rad, |angle increment|
};

/// Steps `dynamics` by `dt` for `seconds` at constant body and virtual rates, recording every step
/// (nothing when `record` is false: settling).
inline std::vector<RateSample> runResonator(ResonatorDynamics* dynamics, double seconds, double body_rate,
                                            double virtual_rate, bool record = true, double dt = 1e-3) {
  std::vector<RateSample> out;
  const long steps = std::lround(seconds / dt);
  if (record) out.reserve(static_cast<std::size_t>(steps));
  ResonatorInputs in;
  in.body_rate_start = in.body_rate_end = body_rate;
  in.virtual_rate = virtual_rate;
  for (long i = 0; i < steps; ++i) {
    const double before = dynamics->wave().theta;
    if (!dynamics->step(dt, in)) break;
    const double after = dynamics->wave().theta;
    if (record) out.push_back({0.5 * (before + after), (after - before) / dt, std::abs(after - before)});
  }
  return out;
}

}  // namespace testing
}  // namespace core
}  // namespace hrg_gyro
