// Test support for the resonator: a shell with every defect at a realistic size, its loops and its
// drive chain; the bound of what the loops' tracking leaves out for a turning wave; forces compared
// component by component; and a run of the closed-loop resonator at 1 kHz that records the angle rate of each
// step against the angle at the step's middle.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "hrg_gyro/core/common/units.h"
#include "hrg_gyro/core/resonator/resonator_dynamics.h"

namespace hrg_gyro {
namespace core {
namespace testing {

struct ResonatorCase {
  ShellParameters shell;
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

/// What the closed form and the first-order lag leave out for a wave turning at `rate` (rad/s): the
/// loops are PI loops, so a source that changes as the wave turns (at 2 |rate|, d(source)/dt^2 =
/// -(2 rate)^2 source) is followed by an effort short by (2 rate)^2 / ki of it, and the quadrature
/// loop's B trails with a phase 2 zeta (2 rate) / wn beyond the first-order lag. Through the drive chain:
///   - the energy loop's effort against the precession force's leak onto the antinode
///     (gamma sin 2th n_v) is short by that much, and leaks back by gamma sin 2th: gamma^2 |rate| (2 rate)^2 / ki_E;
///   - the quadrature loop's effort against the split (Dw/2), turned into precession by the lag phi:
///     (Dw/2) |sin phi| (2 rate)^2 / ki_Q;
///   - the quadrature lag's next order: L |rate| 2 zeta (2 rate) / wn_Q.
inline double loopTrackingBound(const ResonatorCase& c, double rate, double quadrature_lag) {
  const LoopSettings& l = c.loops;
  const double gamma = 0.5 * (c.drive.gain_error_c - c.drive.gain_error_s);
  const double sweep = 2.0 * std::abs(rate);
  const double ki_e = l.integralGain(l.energy_bandwidth), ki_q = l.integralGain(l.quadrature_bandwidth);
  const double energy = l.energy_bandwidth > 0.0 ? gamma * gamma * std::abs(rate) * sweep * sweep / ki_e : 0.0;
  const double quadrature =
      0.5 * std::abs(c.shell.frequency_split * std::sin(c.drive.phase_error)) * sweep * sweep / ki_q;
  const double lag =
      quadrature_lag * std::abs(rate) * 2.0 * l.damping_ratio * sweep / (kTwoPi * l.quadrature_bandwidth);
  return energy + quadrature + lag;
}

/// Each of the four components of `a` within `tolerance` of `b`'s.
inline void expectNear(const WaveFrameForce& a, const WaveFrameForce& b, double tolerance) {
  EXPECT_NEAR(a.antinode_velocity, b.antinode_velocity, tolerance);
  EXPECT_NEAR(a.antinode_displacement, b.antinode_displacement, tolerance);
  EXPECT_NEAR(a.node_velocity, b.node_velocity, tolerance);
  EXPECT_NEAR(a.node_displacement, b.node_displacement, tolerance);
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
